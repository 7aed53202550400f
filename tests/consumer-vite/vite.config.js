import { defineConfig } from 'vite';

// Plain Vite: the package's web build loads its .wasm through
// `new URL(..., import.meta.url)`, which Vite bundles as an asset; no plugin.
export default defineConfig({
  base: './',
  build: { target: 'es2022', chunkSizeWarningLimit: 1024 },
  worker: { format: 'es' },
});
