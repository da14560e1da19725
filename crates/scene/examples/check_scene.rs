//! Checks a scene file and prints its problems or its model (debug form).
//!
//! `cargo run -p clutchpack_scene --example check_scene -- scenes/x.toml [KEY=VALUE ...]`
//! (each extra argument is a `--set` override); `--keys` prints the key reference.

use clutchpack_scene::{keys_doc, load, Override};
use std::path::Path;
use std::process::ExitCode;

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(file) = args.first() else {
        eprintln!("usage: check_scene FILE [KEY=VALUE ...] | --keys");
        return ExitCode::from(2);
    };
    if file == "--keys" {
        print!("{}", keys_doc());
        return ExitCode::SUCCESS;
    }
    let overrides: Result<Vec<Override>, _> = args[1..].iter().map(|a| a.parse()).collect();
    let overrides = match overrides {
        Ok(o) => o,
        Err(e) => {
            eprintln!("{e}");
            return ExitCode::from(2);
        }
    };
    match load(Path::new(file), &overrides) {
        Ok(scene) => {
            println!("{:#?}", scene.pack);
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("{e}");
            ExitCode::FAILURE
        }
    }
}
