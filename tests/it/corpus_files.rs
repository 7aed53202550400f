//! The test corpus in `tests/corpus/` (real CAD files, see its SOURCES.md):
//! the larger files are kept gzipped, and these helpers hand every file
//! out as it was. A file that is missing fails the test that asks for it.

#![allow(dead_code)]

use std::io::Read as _;
use std::path::{Path, PathBuf};

/// The folder of the test corpus.
pub fn corpus_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests").join("corpus")
}

/// The names of the corpus files whose extension is one of `exts` (any
/// case; a gzipped file by the name it has unzipped), sorted.
pub fn corpus_names(exts: &[&str]) -> Vec<String> {
    let entries = std::fs::read_dir(corpus_dir()).unwrap_or_else(|e| panic!("{}: {e}", corpus_dir().display()));
    let mut names: Vec<String> = entries
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .map(|n| n.strip_suffix(".gz").map(String::from).unwrap_or(n))
        .filter(|n| {
            Path::new(n)
                .extension()
                .and_then(|e| e.to_str())
                .is_some_and(|e| exts.iter().any(|x| x.eq_ignore_ascii_case(e)))
        })
        .collect();
    names.sort();
    names
}

/// The bytes of corpus file `name` (read from `name.gz` when it is kept gzipped).
pub fn corpus_bytes(name: &str) -> Vec<u8> {
    let plain = corpus_dir().join(name);
    if let Ok(bytes) = std::fs::read(&plain) {
        return bytes;
    }
    let zipped = corpus_dir().join(format!("{name}.gz"));
    let file = std::fs::File::open(&zipped)
        .unwrap_or_else(|e| panic!("corpus file {name}: neither {} nor {}: {e}", plain.display(), zipped.display()));
    let mut bytes = Vec::new();
    flate2::read::GzDecoder::new(file).read_to_end(&mut bytes).unwrap_or_else(|e| panic!("{}: {e}", zipped.display()));
    bytes
}

/// A path to corpus file `name` as it was, for a program that reads a file:
/// the file itself, or a gzipped one's bytes written under the build's
/// temporary folder.
pub fn corpus_path(name: &str) -> PathBuf {
    let plain = corpus_dir().join(name);
    if plain.is_file() {
        return plain;
    }
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("corpus");
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join(name);
    let bytes = corpus_bytes(name);
    // Written to a name of its own, then moved: tests running at once may want the same file.
    let temp = dir.join(format!(".{name}.{}.{:?}", std::process::id(), std::thread::current().id()));
    std::fs::write(&temp, &bytes).unwrap();
    std::fs::rename(&temp, &out).unwrap();
    out
}

/// Corpus file `name` read as a model (format from its content).
pub fn corpus_model(name: &str) -> surfmesh::Model {
    let bytes = corpus_bytes(name);
    let format = surfmesh::Format::detect(&bytes).unwrap_or_else(|| panic!("{name}: not a model file"));
    surfmesh::read_model(&bytes, format).unwrap_or_else(|e| panic!("{name}: {e}"))
}
