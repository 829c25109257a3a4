//! A fuzzing harness for every parser of the workspace, on stable Rust.
//!
//! Why our own loop and not cargo-fuzz / libFuzzer: libFuzzer needs the nightly compiler
//! (`-Zsanitizer`, `-Cpasses=sancov-module` with `-Z` flags), which this project's machines and
//! CI do not have; afl.rs needs AFL++ built with its LLVM plugins. Both would also need a
//! separate CI step. What we lose is coverage feedback; what stands in for it:
//!
//! - **structure-aware generation**: each target turns `arbitrary` entropy into a well-formed
//!   or nearly well-formed file of its format (a BVH skeleton with human joint names, an MJCF
//!   or URDF element tree over the real vocabulary, an IK config over the real keys, C3D files
//!   from our own writer, npz archives with crafted headers), so most inputs get past the
//!   tokenizer into the semantic stages (FK, role recognition, compile, validation, report);
//! - **byte mutation** (havoc: bit flips, interesting integers and numbers, dictionary tokens,
//!   insertions, deletions, duplications, splices) of seeds, generated files and the corpus;
//! - **outcome feedback**: an input whose result (accepted, or its error message with digits
//!   removed) was never seen joins the corpus, so each new error path becomes a seed.
//!
//! Failures: a panic is caught, counted and saved (`crash-*`); an input running longer than
//! the time limit is a hang (the watchdog saves it and exits); a single allocation larger
//! than [`ALLOCATION_LIMIT`] is an abort (the guard allocator saves the input and refuses,
//! which aborts the process: this is how a count read from a file and trusted shows up).

pub mod amass;
pub mod fbx_target;
mod generate;
pub mod guard;
pub mod motions;
mod mutate;
mod seeds;
pub mod targets;

use std::collections::HashSet;
use std::hash::{Hash, Hasher};
use std::panic::AssertUnwindSafe;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use arbitrary::Unstructured;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

pub use guard::{GuardedAlloc, ALLOCATION_LIMIT};

/// One parser under test.
pub trait Target: Sync {
    fn name(&self) -> &'static str;
    /// Valid files to start from (the project's own fixtures, robots, configs, or files made
    /// by our writers).
    fn seeds(&self) -> Vec<Vec<u8>>;
    /// A structured input from `arbitrary` entropy.
    fn generate(&self, u: &mut Unstructured<'_>) -> arbitrary::Result<Vec<u8>>;
    /// Tokens of the format worth inserting.
    fn dictionary(&self) -> &'static [&'static str];
    /// Parses `input` (and runs the stages that follow on success). `Err` is a clean
    /// rejection with its message; a panic is a bug.
    fn run(&self, input: &[u8]) -> Result<(), String>;
}

/// How long and how to fuzz.
#[derive(Debug, Clone)]
pub struct Options {
    pub executions: u64,
    pub seed: u64,
    /// Longest an input may run before it counts as a hang.
    pub timeout: Duration,
    /// Inputs are cut to this many bytes.
    pub max_len: usize,
    /// Where failing inputs are saved (`None`: not saved).
    pub crash_dir: Option<PathBuf>,
    /// More seeds (e.g. real files given on the command line).
    pub extra_seeds: Vec<Vec<u8>>,
    /// Print a progress line every this many executions (0: never).
    pub progress_every: u64,
}

impl Default for Options {
    fn default() -> Options {
        Options {
            executions: 10_000,
            seed: 0,
            timeout: Duration::from_secs(5),
            max_len: 64 * 1024,
            crash_dir: None,
            extra_seeds: Vec::new(),
            progress_every: 0,
        }
    }
}

/// One failing input.
#[derive(Debug, Clone)]
pub struct Failure {
    pub message: String,
    pub input: Vec<u8>,
    pub saved: Option<PathBuf>,
}

/// What a run did.
#[derive(Debug, Clone, Default)]
pub struct Stats {
    pub executions: u64,
    /// Inputs the parser accepted (and the later stages ran on).
    pub accepted: u64,
    /// Inputs that were structure-generated (the rest are byte mutations).
    pub generated: u64,
    /// Distinct outcomes seen (accepted, or an error message with its digits removed).
    pub outcomes: usize,
    pub corpus: usize,
    pub panics: Vec<Failure>,
    /// Slowest single execution.
    pub slowest: Duration,
    pub seconds: f64,
}

impl Stats {
    #[must_use]
    pub fn line(&self, target: &str) -> String {
        format!(
            "{target}: {} executions in {:.1} s ({:.0}/s), {} accepted, {} generated, {} distinct outcomes, corpus {}, slowest {:.1} ms, {} panics, 0 hangs, 0 aborts",
            self.executions,
            self.seconds,
            self.executions as f64 / self.seconds.max(1e-9),
            self.accepted,
            self.generated,
            self.outcomes,
            self.corpus,
            self.slowest.as_secs_f64() * 1e3,
            self.panics.len()
        )
    }
}

/// What [`next_input`] returns when a generator panicked: [`fuzz`] counts it as a panic.
const GENERATOR_PANIC: &[u8] = b"GENERATOR PANIC";

/// Largest corpus kept (older entries are replaced at random beyond it).
const MAX_CORPUS: usize = 4096;

/// Runs `target` for `options.executions` inputs. Hangs and oversized allocations end the
/// process (after saving the input); panics are caught and returned.
pub fn fuzz(target: &dyn Target, options: &Options) -> Stats {
    let mut rng = ChaCha8Rng::seed_from_u64(options.seed);
    let mut corpus: Vec<Vec<u8>> = target.seeds();
    corpus.extend(options.extra_seeds.iter().cloned());
    corpus.retain(|s| !s.is_empty());
    corpus.iter_mut().for_each(|s| s.truncate(options.max_len));
    if corpus.is_empty() {
        corpus.push(b"\n".to_vec());
    }
    let mut entropy: Vec<Vec<u8>> = Vec::new();
    let mut seen: HashSet<u64> = HashSet::new();
    let mut stats = Stats::default();
    let dictionary = target.dictionary();
    let watchdog = Watchdog::start(target.name(), options);
    guard::set_crash_dir(target.name(), options.crash_dir.as_deref());
    guard::save_input_on_abort();
    let silent = install_quiet_panic_hook();
    let started = Instant::now();
    for exec in 0..options.executions {
        let (input, from_entropy) = next_input(&mut rng, &corpus, &entropy, dictionary, target);
        let mut input = input;
        input.truncate(options.max_len);
        stats.generated += u64::from(from_entropy.is_some());

        watchdog.arm(exec, &input);
        guard::arm(&input);
        let t0 = Instant::now();
        let result = if input == GENERATOR_PANIC {
            Err(Box::new("a generator (one of our writers) panicked")
                as Box<dyn std::any::Any + Send>)
        } else {
            std::panic::catch_unwind(AssertUnwindSafe(|| target.run(&input)))
        };
        let took = t0.elapsed();
        guard::disarm();
        watchdog.disarm();
        stats.slowest = stats.slowest.max(took);

        let signature = match &result {
            Ok(Ok(())) => {
                stats.accepted += 1;
                "accepted".to_owned()
            }
            Ok(Err(message)) => normalise(message),
            Err(payload) => {
                let message = format!("{} ({})", payload_text(payload.as_ref()), silent.take());
                let saved = save(options, target.name(), "crash", exec, &input);
                stats.panics.push(Failure { message, input: input.clone(), saved });
                "panic".to_owned()
            }
        };
        if seen.insert(hash(&signature)) {
            remember(&mut rng, &mut corpus, input);
            if let Some(e) = from_entropy {
                remember(&mut rng, &mut entropy, e);
            }
        } else if let Some(e) = from_entropy.filter(|_| rng.gen_bool(0.01)) {
            remember(&mut rng, &mut entropy, e);
        }
        stats.executions = exec + 1;
        if options.progress_every > 0 && (exec + 1) % options.progress_every == 0 {
            stats.seconds = started.elapsed().as_secs_f64();
            stats.outcomes = seen.len();
            stats.corpus = corpus.len();
            eprintln!("{}", stats.line(target.name()));
        }
    }
    stats.seconds = started.elapsed().as_secs_f64();
    stats.outcomes = seen.len();
    stats.corpus = corpus.len();
    drop(silent);
    watchdog.stop();
    stats
}

fn remember(rng: &mut ChaCha8Rng, pool: &mut Vec<Vec<u8>>, item: Vec<u8>) {
    if pool.len() < MAX_CORPUS {
        pool.push(item);
    } else {
        let at = rng.gen_range(0..pool.len());
        if let Some(slot) = pool.get_mut(at) {
            *slot = item;
        }
    }
}

/// The next input, and the entropy it was generated from when structure-generated.
fn next_input(
    rng: &mut ChaCha8Rng,
    corpus: &[Vec<u8>],
    entropy: &[Vec<u8>],
    dictionary: &[&str],
    target: &dyn Target,
) -> (Vec<u8>, Option<Vec<u8>>) {
    let pick = |rng: &mut ChaCha8Rng, pool: &[Vec<u8>]| -> Vec<u8> {
        pool.get(rng.gen_range(0..pool.len().max(1))).cloned().unwrap_or_default()
    };
    match rng.gen_range(0..10) {
        0..=3 => {
            let mut input = pick(rng, corpus);
            let other = pick(rng, corpus);
            mutate::havoc(rng, &mut input, &other, dictionary);
            (input, None)
        }
        choice => {
            let mut e = if entropy.is_empty() || rng.gen_bool(0.3) {
                let n = rng.gen_range(16..4096);
                (0..n).map(|_| rng.gen()).collect()
            } else {
                let mut e = pick(rng, entropy);
                let other = pick(rng, entropy);
                mutate::havoc(rng, &mut e, &other, &[]);
                e
            };
            if e.is_empty() {
                e.push(0);
            }
            // The generators drive our own writers (C3D, npz): a panic there is a bug too,
            // reported as the input `GENERATOR PANIC` so that the run counts it.
            let generated = std::panic::catch_unwind(AssertUnwindSafe(|| {
                target.generate(&mut Unstructured::new(&e))
            }));
            let mut input = match generated {
                Ok(Ok(input)) => input,
                Ok(Err(_)) => b"\n".to_vec(),
                Err(_) => GENERATOR_PANIC.to_vec(),
            };
            if choice >= 8 {
                let other = pick(rng, corpus);
                mutate::havoc(rng, &mut input, &other, dictionary);
            }
            (input, Some(e))
        }
    }
}

/// An error message with digits removed: `frame 12: ...` and `frame 13: ...` are one outcome.
fn normalise(message: &str) -> String {
    message.chars().filter(|c| !c.is_ascii_digit()).take(120).collect()
}

fn hash(text: &str) -> u64 {
    let mut h = std::collections::hash_map::DefaultHasher::new();
    text.hash(&mut h);
    h.finish()
}

fn payload_text(payload: &(dyn std::any::Any + Send)) -> String {
    payload
        .downcast_ref::<&str>()
        .map(|s| (*s).to_owned())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "panic without a message".to_owned())
}

fn save(options: &Options, target: &str, kind: &str, exec: u64, input: &[u8]) -> Option<PathBuf> {
    let dir = options.crash_dir.as_ref()?;
    std::fs::create_dir_all(dir).ok()?;
    let path = dir.join(format!("{kind}-{target}-{exec}.bin"));
    std::fs::write(&path, input).ok()?;
    Some(path)
}

/// The panic hook during a run records where a panic happened instead of printing it.
struct QuietPanics {
    previous: Arc<Mutex<String>>,
}

impl QuietPanics {
    fn take(&self) -> String {
        self.previous.lock().map(|mut s| std::mem::take(&mut *s)).unwrap_or_default()
    }
}

impl Drop for QuietPanics {
    fn drop(&mut self) {
        if !std::thread::panicking() {
            let _ = std::panic::take_hook();
        }
    }
}

fn install_quiet_panic_hook() -> QuietPanics {
    let last = Arc::new(Mutex::new(String::new()));
    let slot = Arc::clone(&last);
    let verbose = std::env::var_os("RETARGET_FUZZ_VERBOSE").is_some();
    std::panic::set_hook(Box::new(move |info| {
        if verbose {
            eprintln!("{info}");
        }
        let at = info.location().map(|l| format!("at {}:{}", l.file(), l.line()));
        if let Ok(mut s) = slot.lock() {
            *s = at.unwrap_or_default();
        }
    }));
    QuietPanics { previous: last }
}

/// A thread that ends the process when one input runs longer than the time limit, after
/// saving it: an in-process loop cannot interrupt a stuck parser, and a hang is a failure.
struct Watchdog {
    state: Arc<WatchState>,
    thread: Option<std::thread::JoinHandle<()>>,
}

struct WatchState {
    /// Milliseconds since `epoch` when the current input started, or `u64::MAX` when idle.
    started_ms: AtomicU64,
    exec: AtomicU64,
    input: Mutex<Vec<u8>>,
    stop: AtomicBool,
    epoch: Instant,
}

impl Watchdog {
    fn start(target: &'static str, options: &Options) -> Watchdog {
        let state = Arc::new(WatchState {
            started_ms: AtomicU64::new(u64::MAX),
            exec: AtomicU64::new(0),
            input: Mutex::new(Vec::new()),
            stop: AtomicBool::new(false),
            epoch: Instant::now(),
        });
        let watched = Arc::clone(&state);
        let (timeout, options) = (options.timeout, options.clone());
        let thread = std::thread::spawn(move || {
            let limit = u64::try_from(timeout.as_millis()).unwrap_or(u64::MAX);
            while !watched.stop.load(Ordering::SeqCst) {
                std::thread::sleep(Duration::from_millis(50));
                let started = watched.started_ms.load(Ordering::SeqCst);
                let now = u64::try_from(watched.epoch.elapsed().as_millis()).unwrap_or(u64::MAX);
                if started != u64::MAX && now.saturating_sub(started) > limit {
                    let exec = watched.exec.load(Ordering::SeqCst);
                    let input = watched.input.lock().map(|i| i.clone()).unwrap_or_default();
                    let saved = save(&options, target, "hang", exec, &input);
                    eprintln!(
                        "{target}: HANG: execution {exec} ran longer than {timeout:?}; input {}",
                        saved.map_or("not saved".to_owned(), |p| p.display().to_string())
                    );
                    std::process::exit(70);
                }
            }
        });
        Watchdog { state, thread: Some(thread) }
    }

    fn arm(&self, exec: u64, input: &[u8]) {
        if let Ok(mut slot) = self.state.input.lock() {
            slot.clear();
            slot.extend_from_slice(input);
        }
        self.state.exec.store(exec, Ordering::SeqCst);
        let now = u64::try_from(self.state.epoch.elapsed().as_millis()).unwrap_or(0);
        self.state.started_ms.store(now, Ordering::SeqCst);
    }

    fn disarm(&self) {
        self.state.started_ms.store(u64::MAX, Ordering::SeqCst);
    }

    fn stop(mut self) {
        self.state.stop.store(true, Ordering::SeqCst);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}
