//! `retarget-fuzz TARGET N [--seed S] [--timeout-ms T] [--crashes DIR] [--seeds DIR]...`:
//! runs one fuzz target (or `all`, one after another) for N executions and prints one line
//! per target. Exit codes: 0 clean, 1 panics found, 2 usage; a hang exits with 70 and an
//! oversized allocation aborts (both after saving the input). See `scripts/fuzz`.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

#[global_allocator]
static ALLOC: fuzz::GuardedAlloc = fuzz::GuardedAlloc;

fn usage() -> ExitCode {
    let names: Vec<&str> = fuzz::targets::all().iter().map(|t| t.name()).collect();
    eprintln!(
        "usage: retarget-fuzz TARGET N [--seed S] [--timeout-ms T] [--crashes DIR] [--seeds DIR]\n\
         targets: {} | all",
        names.join(" | ")
    );
    ExitCode::from(2)
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (Some(target), Some(count)) = (args.first(), args.get(1).and_then(|n| n.parse().ok()))
    else {
        return usage();
    };
    let mut options = fuzz::Options {
        executions: count,
        crash_dir: Some(PathBuf::from("target/fuzz")),
        progress_every: count.div_ceil(10).max(1),
        ..fuzz::Options::default()
    };
    let mut seed_dirs = Vec::new();
    let mut rest = args.iter().skip(2);
    while let Some(flag) = rest.next() {
        let Some(value) = rest.next() else { return usage() };
        match flag.as_str() {
            "--seed" => match value.parse() {
                Ok(s) => options.seed = s,
                Err(_) => return usage(),
            },
            "--timeout-ms" => match value.parse() {
                Ok(ms) => options.timeout = Duration::from_millis(ms),
                Err(_) => return usage(),
            },
            "--crashes" => options.crash_dir = Some(PathBuf::from(value)),
            "--seeds" => seed_dirs.push(PathBuf::from(value)),
            _ => return usage(),
        }
    }
    let targets = if target == "all" {
        fuzz::targets::all()
    } else {
        match fuzz::targets::by_name(target) {
            Some(t) => vec![t],
            None => return usage(),
        }
    };
    let mut failed = false;
    for target in targets {
        let mut run = options.clone();
        run.extra_seeds = seed_dirs.iter().flat_map(|d| seeds_in(d, target.name())).collect();
        let stats = fuzz::fuzz(target.as_ref(), &run);
        println!("{}", stats.line(target.name()));
        for failure in &stats.panics {
            failed = true;
            let saved =
                failure.saved.as_ref().map_or("not saved".to_owned(), |p| p.display().to_string());
            println!("  PANIC: {} (input: {saved})", failure.message);
        }
    }
    if failed {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    }
}

/// Files of `dir` whose extension fits the target (e.g. real C3D files as extra seeds).
fn seeds_in(dir: &std::path::Path, target: &str) -> Vec<Vec<u8>> {
    let extension = match target {
        "mjcf" => "xml",
        "config" => "json",
        other => other,
    };
    let Ok(entries) = std::fs::read_dir(dir) else { return Vec::new() };
    let mut paths: Vec<PathBuf> = entries
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|e| e.eq_ignore_ascii_case(extension)))
        .collect();
    paths.sort();
    paths.iter().filter_map(|p| std::fs::read(p).ok()).collect()
}
