//! The CI pass of the fuzz harness: every parser, 20,000 inputs each with a fixed seed (a
//! few seconds per parser in release mode), structure-generated and byte-mutated. Any panic,
//! hang (over 10 s for one input) or oversized allocation fails the test run. Long runs:
//! `scripts/fuzz TARGET N`.

#[global_allocator]
static ALLOC: fuzz::GuardedAlloc = fuzz::GuardedAlloc;

const EXECUTIONS: u64 = 20_000;

#[test]
fn every_parser_survives_a_short_fuzz_pass() {
    let crashes = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("fuzz");
    replay_regressions();
    let targets = fuzz::targets::all();
    let names: Vec<&str> = targets.iter().map(|t| t.name()).collect();
    assert_eq!(
        names,
        ["bvh", "c3d", "mjcf", "urdf", "config", "npz", "fbx", "amass", "pickle", "csv"]
    );
    for target in targets {
        let options = fuzz::Options {
            executions: EXECUTIONS,
            seed: 15,
            timeout: std::time::Duration::from_secs(10),
            crash_dir: Some(crashes.clone()),
            ..fuzz::Options::default()
        };
        let stats = fuzz::fuzz(target.as_ref(), &options);
        eprintln!("{}", stats.line(target.name()));
        assert_eq!(stats.executions, EXECUTIONS);
        let panics: Vec<String> = stats
            .panics
            .iter()
            .map(|f| format!("{} (input saved as {:?})", f.message, f.saved))
            .collect();
        assert!(panics.is_empty(), "{}: {panics:#?}", target.name());
        // The generators must reach the stages after parsing, not only the tokenizer.
        assert!(
            stats.accepted * 50 > EXECUTIONS,
            "{}: only {} of {EXECUTIONS} inputs accepted",
            target.name(),
            stats.accepted
        );
        assert!(stats.generated * 3 > EXECUTIONS, "{}: {stats:?}", target.name());
    }
}

/// Inputs that once crashed a parser (`tests/regressions/<target>-<what>.bin`, found by the
/// fuzzer or by hand), replayed under the allocation guard: each must be a clean result.
fn replay_regressions() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/regressions");
    let mut replayed = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let target_name = name.split('-').next().unwrap();
        let target = fuzz::targets::by_name(target_name).unwrap_or_else(|| panic!("{name}"));
        let input = std::fs::read(&path).unwrap();
        fuzz::guard::arm(&input);
        let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| target.run(&input)));
        fuzz::guard::disarm();
        let result = result.unwrap_or_else(|_| panic!("{name}: panicked"));
        eprintln!("regression {name}: {result:?}");
        assert!(result.is_err(), "{name}: a crafted file is an error");
        replayed += 1;
    }
    assert!(replayed >= 2, "{replayed} regression inputs in {}", dir.display());
}
