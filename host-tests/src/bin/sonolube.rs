//! `sonolube`: the host command-line tool.

fn main() {
    eprintln!("usage: sonolube <command> ...");
    std::process::exit(2);
}
