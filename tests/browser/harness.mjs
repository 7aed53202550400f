// Shared by the browser tests: Debian's chromium through playwright-core (no
// downloaded browser), the repository's static server on a free port, and a
// screenshot folder (tests/browser/screenshots/, git-ignored).

import { mkdirSync } from 'node:fs';
import { dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';
import { serve } from '../../scripts/serve.mjs';

export const here = dirname(fileURLToPath(import.meta.url));
export const root = join(here, '..', '..');
export const shots = join(here, 'screenshots');

const CHROMIUM = process.env.CHROMIUM ?? '/usr/bin/chromium';
const FLAGS = [
  '--headless',
  '--no-sandbox',
  '--disable-gpu',
  '--disable-background-networking',
  '--disable-component-update',
  '--disable-sync',
  '--no-first-run',
  // Headless Chromium 156 otherwise keeps reloading its (never shown) omnibox
  // popup WebUI in a renderer of its own, which kept one of this machine's two
  // cores busy through every page load and slowed the page's first mesh by a third.
  '--disable-features=WebUIOmniboxPopup,WebUIOmniboxAimPopup',
];

/** Starts the server (page, package, three.js, plus `mounts`) and the browser. */
export async function start(mounts = []) {
  mkdirSync(shots, { recursive: true });
  const { server, url } = await serve({
    port: 0,
    quiet: true,
    mounts: [['/pkg/', 'pkg'], ['/vendor/three/', 'node_modules/three'], ['/', 'www'], ...mounts],
  });
  const browser = await chromium.launch({ executablePath: CHROMIUM, args: FLAGS });
  return {
    url,
    browser,
    async stop() {
      await browser.close();
      await new Promise((done) => server.close(done));
    },
  };
}

/** A page that fails the test on an uncaught error and keeps console errors for the message. */
export async function open(browser, url, { width = 1400, height = 860 } = {}) {
  const context = await browser.newContext({ viewport: { width, height }, acceptDownloads: true });
  const page = await context.newPage();
  page.errors = [];
  page.on('pageerror', (e) => page.errors.push(`uncaught: ${e.message}`));
  page.on('console', (m) => {
    if (m.type() === 'error') page.errors.push(`console: ${m.text()}`);
  });
  await page.goto(url);
  return page;
}

export function shot(page, name) {
  return page.screenshot({ path: join(shots, `${name}.png`) });
}
