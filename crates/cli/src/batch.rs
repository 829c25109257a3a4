//! The dataset engine behind `retarget batch`: walk a tree, shard it, skip finished clips,
//! convert the rest in parallel with failure isolation, and summarise.
//!
//! It is generic over the per-clip conversion (a closure), so its bookkeeping (resume,
//! shards, summaries, progress) is tested without running the solver.

use std::collections::BTreeMap;
use std::fmt;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::str::FromStr;
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::Instant;

use anyhow::{bail, Context};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// `--shard K/N`: this process handles the files whose index in the sorted list is K mod N.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    pub index: usize,
    pub count: usize,
}

impl FromStr for Shard {
    type Err = String;

    fn from_str(s: &str) -> Result<Shard, String> {
        let (k, n) = s.split_once('/').ok_or_else(|| format!("expected K/N, got `{s}`"))?;
        let index: usize = k.trim().parse().map_err(|_| format!("`{k}` is not a shard index"))?;
        let count: usize = n.trim().parse().map_err(|_| format!("`{n}` is not a shard count"))?;
        if count == 0 || index >= count {
            return Err(format!("shard {index}/{count}: need 0 <= K < N"));
        }
        Ok(Shard { index, count })
    }
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

/// What a conversion reports about one clip.
#[derive(Debug, Clone, Default)]
pub struct ClipResult {
    pub frames: usize,
    /// Quality metrics (the report's JSON), stored as is in the summary.
    pub metrics: serde_json::Value,
    /// What was inferred about the source, one line (`fk::FkReport::inferred`).
    pub inferred: Option<String>,
    /// The report's verdict, when the clip was measured.
    pub verdict: Option<ClipVerdict>,
}

/// A clip's verdict in `summary.json`: ok, or the names of the checks that broke their caps
/// (their values and caps are in the row's `metrics.verdict`).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct ClipVerdict {
    pub ok: bool,
    pub flags: Vec<String>,
}

/// One row of `summary.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ClipSummary {
    /// Input path relative to the input directory, `/`-separated.
    pub input: String,
    /// Output path relative to the output directory.
    pub output: String,
    /// `converted`, `skipped` (output already there) or `failed`.
    pub status: String,
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub frames: Option<usize>,
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub seconds: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub frames_per_second: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub verdict: Option<ClipVerdict>,
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub metrics: Option<serde_json::Value>,
    /// Up axis, unit, skeleton roles and rest pose inferred from the source.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub inferred: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub error: Option<String>,
}

/// `summary.json` of one run (or of several shards merged).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
pub struct Summary {
    pub robot: String,
    pub format: String,
    /// `K/N` per shard that contributed.
    pub shards: Vec<String>,
    pub clips: Vec<ClipSummary>,
    pub totals: Totals,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
pub struct Totals {
    pub clips: usize,
    pub converted: usize,
    pub skipped: usize,
    pub failed: usize,
    /// Frames converted in this run (skipped clips not counted).
    pub frames: usize,
    /// Wall time of the run(s), seconds (merged: the sum over shards).
    pub seconds: f64,
    /// Converted clips whose verdict is not ok, and per check name how many clips broke it.
    #[serde(default)]
    pub flagged: usize,
    #[serde(default)]
    pub flags: BTreeMap<String, usize>,
}

impl Summary {
    fn recount(&mut self) {
        let count = |s: &str| self.clips.iter().filter(|c| c.status == s).count();
        self.totals.clips = self.clips.len();
        self.totals.converted = count("converted");
        self.totals.skipped = count("skipped");
        self.totals.failed = count("failed");
        self.totals.frames =
            self.clips.iter().filter(|c| c.status == "converted").filter_map(|c| c.frames).sum();
        let verdicts = || self.clips.iter().filter_map(|c| c.verdict.as_ref());
        self.totals.flagged = verdicts().filter(|v| !v.ok).count();
        self.totals.flags.clear();
        for name in verdicts().flat_map(|v| &v.flags) {
            *self.totals.flags.entry(name.clone()).or_default() += 1;
        }
    }

    /// Converted clips whose verdict is not ok.
    pub fn flagged(&self) -> impl Iterator<Item = &ClipSummary> {
        self.clips.iter().filter(|c| c.verdict.as_ref().is_some_and(|v| !v.ok))
    }

    /// The name of the summary file a run writes into the output directory.
    #[must_use]
    pub fn file_name(shard: Option<Shard>) -> String {
        match shard {
            None => "summary.json".to_string(),
            Some(s) => format!("summary-shard-{}-of-{}.json", s.index, s.count),
        }
    }

    /// Combine shard summaries (`retarget batch --merge-summaries`): clips sorted by input,
    /// a clip present in several keeps its most informative row (converted > skipped > failed).
    pub fn merge(parts: &[Summary]) -> anyhow::Result<Summary> {
        let Some(first) = parts.first() else { bail!("no summaries to merge") };
        let mut by_input: BTreeMap<String, ClipSummary> = BTreeMap::new();
        let rank = |s: &str| match s {
            "converted" => 2,
            "skipped" => 1,
            _ => 0,
        };
        let mut merged = Summary {
            robot: first.robot.clone(),
            format: first.format.clone(),
            ..Summary::default()
        };
        for part in parts {
            if part.robot != first.robot || part.format != first.format {
                bail!(
                    "summaries disagree: robot {} / format {} vs robot {} / format {}",
                    first.robot,
                    first.format,
                    part.robot,
                    part.format
                );
            }
            merged.shards.extend(part.shards.iter().cloned());
            merged.totals.seconds += part.totals.seconds;
            for clip in &part.clips {
                let keep = by_input
                    .get(&clip.input)
                    .is_none_or(|old| rank(&clip.status) > rank(&old.status));
                if keep {
                    by_input.insert(clip.input.clone(), clip.clone());
                }
            }
        }
        merged.clips = by_input.into_values().collect();
        merged.recount();
        Ok(merged)
    }
}

/// Every file under `root` whose extension is one of `extensions` (case-insensitive),
/// sorted by relative path so that shards and summaries are deterministic.
pub fn walk(root: &Path, extensions: &[&str]) -> anyhow::Result<Vec<PathBuf>> {
    let mut found = Vec::new();
    let mut stack = vec![root.to_path_buf()];
    while let Some(dir) = stack.pop() {
        let entries = std::fs::read_dir(&dir)
            .with_context(|| format!("{}: cannot list directory", dir.display()))?;
        for entry in entries {
            let entry =
                entry.with_context(|| format!("{}: cannot list directory", dir.display()))?;
            let path = entry.path();
            let kind =
                entry.file_type().with_context(|| format!("{}: cannot stat", path.display()))?;
            if kind.is_dir() {
                stack.push(path);
            } else if has_extension(&path, extensions) {
                found.push(path.strip_prefix(root).unwrap_or(&path).to_path_buf());
            }
        }
    }
    found.sort();
    Ok(found)
}

fn has_extension(path: &Path, extensions: &[&str]) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| extensions.iter().any(|x| x.eq_ignore_ascii_case(e)))
}

/// The files of `shard` among `files` (all of them without a shard).
#[must_use]
pub fn select_shard(files: Vec<PathBuf>, shard: Option<Shard>) -> Vec<PathBuf> {
    match shard {
        None => files,
        Some(s) => files
            .into_iter()
            .enumerate()
            .filter(|(i, _)| i % s.count == s.index)
            .map(|(_, f)| f)
            .collect(),
    }
}

/// What a run is asked to do.
pub struct Plan<'a> {
    pub input_dir: &'a Path,
    pub output_dir: &'a Path,
    pub files: Vec<PathBuf>,
    /// Output extension, e.g. `npz`.
    pub extension: &'a str,
    pub overwrite: bool,
    pub jobs: usize,
    pub robot: &'a str,
    pub shard: Option<Shard>,
}

fn rel_string(path: &Path) -> String {
    path.components().map(|c| c.as_os_str().to_string_lossy()).collect::<Vec<_>>().join("/")
}

/// Run `convert(input, output)` on every planned clip, `jobs` at a time. A clip whose output
/// exists is skipped unless `overwrite`. Failures are recorded and the run goes on. Writes
/// the summary file into the output directory (atomically) and returns it.
pub fn run<F>(plan: &Plan<'_>, convert: F) -> anyhow::Result<Summary>
where
    F: Fn(&Path, &Path) -> anyhow::Result<ClipResult> + Sync,
{
    let started = Instant::now();
    std::fs::create_dir_all(plan.output_dir).with_context(|| {
        format!("{}: cannot create output directory", plan.output_dir.display())
    })?;
    let progress = Progress::new(plan.files.len());
    let pool = rayon::ThreadPoolBuilder::new().num_threads(plan.jobs.max(1)).build()?;
    let rows: Vec<ClipSummary> = pool.install(|| {
        plan.files.par_iter().map(|rel| convert_one(plan, rel, &convert, &progress)).collect()
    });
    progress.finish();
    let mut summary = Summary {
        robot: plan.robot.to_string(),
        format: plan.extension.to_string(),
        shards: vec![plan.shard.map_or_else(|| "0/1".to_string(), |s| s.to_string())],
        clips: rows,
        totals: Totals::default(),
    };
    summary.recount();
    summary.totals.seconds = started.elapsed().as_secs_f64();
    let path = plan.output_dir.join(Summary::file_name(plan.shard));
    let text = serde_json::to_string_pretty(&summary)? + "\n";
    crate::atomic_write(&path, text.as_bytes())?;
    Ok(summary)
}

fn convert_one<F>(plan: &Plan<'_>, rel: &Path, convert: &F, progress: &Progress) -> ClipSummary
where
    F: Fn(&Path, &Path) -> anyhow::Result<ClipResult>,
{
    let input = plan.input_dir.join(rel);
    let rel_out = rel.with_extension(plan.extension);
    let output = plan.output_dir.join(&rel_out);
    let mut row = ClipSummary {
        input: rel_string(rel),
        output: rel_string(&rel_out),
        status: "skipped".to_string(),
        frames: None,
        seconds: None,
        frames_per_second: None,
        verdict: None,
        metrics: None,
        inferred: None,
        error: None,
    };
    if output.is_file() && !plan.overwrite {
        progress.clip_done(&row.input, "skipped (output exists)", 0);
        return row;
    }
    let started = Instant::now();
    let result = output
        .parent()
        .map_or(Ok(()), std::fs::create_dir_all)
        .with_context(|| format!("{}: cannot create directory", output.display()))
        .and_then(|()| convert_isolated(convert, &input, &output));
    let seconds = started.elapsed().as_secs_f64();
    match result {
        Ok(clip) => {
            row.status = "converted".to_string();
            row.frames = Some(clip.frames);
            row.seconds = Some(seconds);
            row.frames_per_second = Some(clip.frames as f64 / seconds.max(1e-9));
            row.metrics = Some(clip.metrics);
            row.verdict = clip.verdict;
            let inferred = clip.inferred.as_deref().map_or(String::new(), |i| format!("; {i}"));
            progress.clip_done(
                &row.input,
                &format!("{} frames in {seconds:.2} s{inferred}", clip.frames),
                clip.frames,
            );
            row.inferred = clip.inferred;
        }
        Err(err) => {
            row.status = "failed".to_string();
            let error = crate::errors::error_chain(&err);
            progress.clip_done(&row.input, &format!("FAILED: {error}"), 0);
            row.error = Some(error);
        }
    }
    row
}

/// `convert(input, output)` with a panic turned into this clip's error: the library crates
/// promise not to panic on input, and should that promise break, one clip fails (with the
/// panic's message, to report) while the batch goes on and writes its summary.
fn convert_isolated<F>(convert: &F, input: &Path, output: &Path) -> anyhow::Result<ClipResult>
where
    F: Fn(&Path, &Path) -> anyhow::Result<ClipResult>,
{
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| convert(input, output)))
        .unwrap_or_else(|payload| {
            let message = payload
                .downcast_ref::<&str>()
                .map(|s| (*s).to_owned())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "no message".to_owned());
            bail!("{}: internal error (a bug, please report it): {message}", input.display())
        })
}

/// A progress bar on a terminal, plain log lines otherwise.
struct Progress {
    bar: Option<indicatif::ProgressBar>,
    total: usize,
    done: AtomicUsize,
    frames: AtomicU64,
    started: Instant,
    log: Mutex<()>,
}

impl Progress {
    fn new(total: usize) -> Progress {
        let bar = std::io::stderr().is_terminal().then(|| {
            let bar = indicatif::ProgressBar::new(total as u64);
            let style = indicatif::ProgressStyle::with_template(
                "{bar:40} {pos}/{len} clips  {msg}  elapsed {elapsed}  ETA {eta}",
            )
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar());
            bar.set_style(style);
            bar
        });
        Progress {
            bar,
            total,
            done: AtomicUsize::new(0),
            frames: AtomicU64::new(0),
            started: Instant::now(),
            log: Mutex::new(()),
        }
    }

    fn clip_done(&self, name: &str, what: &str, frames: usize) {
        let done = self.done.fetch_add(1, Ordering::SeqCst) + 1;
        let frames = self.frames.fetch_add(frames as u64, Ordering::SeqCst) + frames as u64;
        let rate = frames as f64 / self.started.elapsed().as_secs_f64().max(1e-9);
        match &self.bar {
            Some(bar) => {
                bar.set_message(format!("{rate:.0} frames/s"));
                bar.inc(1);
                if what.starts_with("FAILED") {
                    bar.println(format!("{name}: {what}"));
                }
            }
            None => {
                let _guard = self.log.lock();
                eprintln!("[{done}/{}] {name}: {what} ({rate:.0} frames/s overall)", self.total);
            }
        }
    }

    fn finish(&self) {
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tree(files: &[&str]) -> tempdir::Dir {
        let dir = tempdir::Dir::new();
        for f in files {
            let p = dir.path().join(f);
            std::fs::create_dir_all(p.parent().unwrap()).unwrap();
            std::fs::write(p, f).unwrap();
        }
        dir
    }

    /// A tiny self-cleaning temporary directory (no extra dependency).
    mod tempdir {
        use std::path::{Path, PathBuf};
        use std::sync::atomic::{AtomicUsize, Ordering};

        pub struct Dir(PathBuf);
        static NEXT: AtomicUsize = AtomicUsize::new(0);

        impl Dir {
            pub fn new() -> Dir {
                let n = NEXT.fetch_add(1, Ordering::SeqCst);
                let p = std::env::temp_dir()
                    .join(format!("retarget-batch-test-{}-{n}", std::process::id()));
                let _ = std::fs::remove_dir_all(&p);
                std::fs::create_dir_all(&p).unwrap();
                Dir(p)
            }
            pub fn path(&self) -> &Path {
                &self.0
            }
        }
        impl Drop for Dir {
            fn drop(&mut self) {
                let _ = std::fs::remove_dir_all(&self.0);
            }
        }
    }

    #[test]
    fn walk_finds_motion_files_sorted_and_relative() {
        let dir = tree(&["b/2.bvh", "a.BVH", "b/1.bvh", "notes.txt", "c/d/e.bvh"]);
        let files = walk(dir.path(), &["bvh"]).unwrap();
        let names: Vec<String> = files.iter().map(|p| rel_string(p)).collect();
        assert_eq!(names, ["a.BVH", "b/1.bvh", "b/2.bvh", "c/d/e.bvh"]);
    }

    #[test]
    fn shards_partition_the_files() {
        let files: Vec<PathBuf> = (0..10).map(|i| PathBuf::from(format!("{i}.bvh"))).collect();
        let mut seen = Vec::new();
        for k in 0..3 {
            seen.extend(select_shard(files.clone(), Some(Shard { index: k, count: 3 })));
        }
        seen.sort();
        let mut all = files.clone();
        all.sort();
        assert_eq!(seen, all);
        assert_eq!(select_shard(files.clone(), Some(Shard { index: 1, count: 3 })).len(), 3);
    }

    #[test]
    fn shard_parsing_rejects_out_of_range() {
        assert_eq!("2/4".parse::<Shard>(), Ok(Shard { index: 2, count: 4 }));
        assert!("4/4".parse::<Shard>().is_err());
        assert!("1/0".parse::<Shard>().is_err());
        assert!("x".parse::<Shard>().is_err());
    }

    fn plan<'a>(input: &'a Path, output: &'a Path, overwrite: bool) -> Plan<'a> {
        Plan {
            input_dir: input,
            output_dir: output,
            files: walk(input, &["bvh"]).unwrap(),
            extension: "out",
            overwrite,
            jobs: 2,
            robot: "test_robot",
            shard: None,
        }
    }

    fn fake_convert(input: &Path, output: &Path) -> anyhow::Result<ClipResult> {
        let text = std::fs::read_to_string(input)?;
        if text.contains("bad") {
            bail!("{}: cannot convert", input.display());
        }
        if text.contains("panic") {
            panic!("a bug met {}", text.len());
        }
        crate::atomic_write(output, text.to_uppercase().as_bytes())?;
        let flagged = text.contains("flag");
        let flags = if flagged { vec!["self_collision".to_owned()] } else { Vec::new() };
        Ok(ClipResult {
            frames: text.len(),
            metrics: serde_json::json!({"len": text.len()}),
            inferred: None,
            verdict: Some(ClipVerdict { ok: !flagged, flags }),
        })
    }

    #[test]
    fn verdicts_are_written_and_counted_per_flag() {
        let input = tree(&["a.bvh", "b/flagged.bvh", "c_flagged.bvh"]);
        let output = tempdir::Dir::new();
        let summary = run(&plan(input.path(), output.path(), false), fake_convert).unwrap();
        assert_eq!((summary.totals.converted, summary.totals.flagged), (3, 2));
        assert_eq!(summary.totals.flags.get("self_collision"), Some(&2));
        let names: Vec<&str> = summary.flagged().map(|c| c.input.as_str()).collect();
        assert_eq!(names, ["b/flagged.bvh", "c_flagged.bvh"]);
        let written: serde_json::Value = serde_json::from_str(
            &std::fs::read_to_string(output.path().join("summary.json")).unwrap(),
        )
        .unwrap();
        assert_eq!(written["clips"][0]["verdict"]["ok"], true);
        assert_eq!(written["clips"][1]["verdict"]["flags"][0], "self_collision");
        assert_eq!(written["totals"]["flagged"], 2);
        // A resumed run skips the clips and so measures none: nothing flagged.
        let again = run(&plan(input.path(), output.path(), false), fake_convert).unwrap();
        assert_eq!((again.totals.skipped, again.totals.flagged), (3, 0));
    }

    #[test]
    fn failures_are_isolated_and_resume_skips_finished_clips() {
        let input = tree(&["x/good.bvh", "x/bad.bvh", "y.bvh"]);
        let output = tempdir::Dir::new();
        let first = run(&plan(input.path(), output.path(), false), fake_convert).unwrap();
        assert_eq!((first.totals.converted, first.totals.failed, first.totals.skipped), (2, 1, 0));
        let failed = first.clips.iter().find(|c| c.status == "failed").unwrap();
        assert_eq!(failed.input, "x/bad.bvh");
        assert!(failed.error.as_deref().unwrap().contains("cannot convert"));
        assert_eq!(
            std::fs::read_to_string(output.path().join("x/good.out")).unwrap(),
            "X/GOOD.BVH"
        );

        let second = run(&plan(input.path(), output.path(), false), fake_convert).unwrap();
        assert_eq!(
            (second.totals.converted, second.totals.failed, second.totals.skipped),
            (0, 1, 2)
        );
        let third = run(&plan(input.path(), output.path(), true), fake_convert).unwrap();
        assert_eq!(third.totals.converted, 2);

        let written: Summary = serde_json::from_str(
            &std::fs::read_to_string(output.path().join("summary.json")).unwrap(),
        )
        .unwrap();
        assert_eq!(written, third);
    }

    /// Issue 15: a panic in one clip's conversion must not take the batch down.
    #[test]
    fn a_panicking_clip_fails_alone_and_the_summary_is_written() {
        let input = tree(&["a.bvh", "b/panic.bvh", "c.bvh"]);
        let output = tempdir::Dir::new();
        let summary = run(&plan(input.path(), output.path(), false), fake_convert).unwrap();
        assert_eq!((summary.totals.converted, summary.totals.failed), (2, 1));
        let failed = summary.clips.iter().find(|c| c.status == "failed").unwrap();
        assert_eq!(failed.input, "b/panic.bvh");
        let error = failed.error.as_deref().unwrap();
        assert!(
            error.ends_with("panic.bvh: internal error (a bug, please report it): a bug met 11"),
            "{error}"
        );
        assert!(!output.path().join("b/panic.out").exists());
        let written: Summary = serde_json::from_str(
            &std::fs::read_to_string(output.path().join("summary.json")).unwrap(),
        )
        .unwrap();
        assert_eq!(written, summary);
    }

    #[test]
    fn merging_shards_prefers_converted_rows() {
        let row = |input: &str, status: &str| ClipSummary {
            input: input.into(),
            output: input.into(),
            status: status.into(),
            frames: (status == "converted").then_some(10),
            seconds: None,
            frames_per_second: None,
            verdict: None,
            metrics: None,
            inferred: None,
            error: None,
        };
        let a = Summary {
            robot: "g1".into(),
            format: "npz".into(),
            shards: vec!["0/2".into()],
            clips: vec![row("a", "converted"), row("c", "skipped")],
            totals: Totals { seconds: 1.0, ..Totals::default() },
        };
        let b = Summary {
            shards: vec!["1/2".into()],
            clips: vec![row("b", "failed"), row("c", "converted")],
            totals: Totals { seconds: 2.0, ..Totals::default() },
            ..a.clone()
        };
        let m = Summary::merge(&[a.clone(), b]).unwrap();
        assert_eq!(m.clips.iter().map(|c| c.input.as_str()).collect::<Vec<_>>(), ["a", "b", "c"]);
        assert_eq!(m.clips[2].status, "converted");
        assert_eq!((m.totals.converted, m.totals.failed, m.totals.frames), (2, 1, 20));
        assert_eq!(m.totals.seconds, 3.0);
        let other = Summary { robot: "t1".into(), ..a };
        assert!(Summary::merge(&[m, other]).is_err());
    }
}
