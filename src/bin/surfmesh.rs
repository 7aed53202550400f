//! The `surfmesh` command line.

fn main() {
    eprintln!("surfmesh: not written yet");
    std::process::exit(2);
}
