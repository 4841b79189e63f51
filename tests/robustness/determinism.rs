//! The same inputs give the same bytes with 1 and with 2 worker threads
//! (issue 22, STYLE §18): `waam slice` and `waam plan` are run with
//! `RAYON_NUM_THREADS=1` and `=2` and every file they write is compared,
//! byte for byte, except the wall times of `summary.json` (its `run_time_s`
//! object and each layer's solver `time_s`, removed before the JSON values
//! are compared).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use crate::common::{part_path, waam};

/// Every file under `dir`, by path relative to it.
fn files_under(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    let mut out = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).unwrap_or_else(|e| panic!("{}: {e}", d.display())) {
            let p = entry.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                let rel = p.strip_prefix(dir).unwrap().to_path_buf();
                out.insert(rel, std::fs::read(&p).unwrap());
            }
        }
    }
    out
}

/// Runs `waam <args> --out <dir>/<threads>` with `threads` rayon workers
/// and returns the files written.
fn run(args: &[&str], dir: &Path, threads: usize) -> BTreeMap<PathBuf, Vec<u8>> {
    let out = dir.join(format!("threads-{threads}"));
    let result = waam()
        .env("RAYON_NUM_THREADS", threads.to_string())
        .arg("--quiet")
        .args(args)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        result.status.success(),
        "{args:?} with {threads} thread(s): {}",
        String::from_utf8_lossy(&result.stderr)
    );
    files_under(&out)
}

/// `summary.json` without its wall times: the top-level `run_time_s` and
/// every `time_s` (the solver's time per layer).
fn summary_without_times(bytes: &[u8]) -> serde_json::Value {
    fn strip(v: &mut serde_json::Value) {
        match v {
            serde_json::Value::Object(m) => {
                m.remove("time_s");
                m.values_mut().for_each(strip);
            }
            serde_json::Value::Array(a) => a.iter_mut().for_each(strip),
            _ => {}
        }
    }
    let mut v: serde_json::Value = serde_json::from_slice(bytes).expect("summary.json is JSON");
    let removed = v
        .as_object_mut()
        .expect("summary.json is an object")
        .remove("run_time_s");
    assert!(removed.is_some(), "summary.json has no run_time_s");
    strip(&mut v);
    v
}

/// The first place where two JSON values differ, as a path (`a/3/b`).
fn first_difference(a: &serde_json::Value, b: &serde_json::Value, at: String) -> Option<String> {
    use serde_json::Value;
    match (a, b) {
        (Value::Object(x), Value::Object(y)) => {
            if x.keys().ne(y.keys()) {
                return Some(format!("{at}: keys differ"));
            }
            x.iter()
                .find_map(|(k, v)| first_difference(v, &y[k], format!("{at}/{k}")))
        }
        (Value::Array(x), Value::Array(y)) if x.len() == y.len() => x
            .iter()
            .zip(y)
            .enumerate()
            .find_map(|(i, (v, w))| first_difference(v, w, format!("{at}/{i}"))),
        _ => (a != b).then(|| format!("{at}: {a} vs {b}")),
    }
}

fn assert_same(one: &BTreeMap<PathBuf, Vec<u8>>, two: &BTreeMap<PathBuf, Vec<u8>>, what: &str) {
    assert_eq!(
        one.keys().collect::<Vec<_>>(),
        two.keys().collect::<Vec<_>>(),
        "{what}: not the same files"
    );
    assert!(one.len() >= 2, "{what}: only {:?}", one.keys());
    for (name, a) in one {
        let b = &two[name];
        if name.file_name().is_some_and(|n| n == "summary.json") {
            let (a, b) = (summary_without_times(a), summary_without_times(b));
            if let Some(d) = first_difference(&a, &b, String::new()) {
                panic!("{what}: {} differs at {d}", name.display());
            }
        } else {
            assert!(
                a == b,
                "{what}: {} differs between 1 and 2 threads",
                name.display()
            );
        }
    }
}

#[test]
fn slice_writes_the_same_bytes_with_one_and_two_threads() {
    let dir = tempfile::tempdir().unwrap();
    let part = part_path("quarter-torus.toml");
    let args = [
        "slice",
        part.to_str().unwrap(),
        "--delta",
        "3",
        "--points",
        "90",
    ];
    let one = run(&args, dir.path(), 1);
    let two = run(&args, dir.path(), 2);
    assert!(one.contains_key(Path::new("path.csv")), "{:?}", one.keys());
    assert_same(&one, &two, "slice");
}

#[test]
fn plan_writes_the_same_bytes_with_one_and_two_threads() {
    let dir = tempfile::tempdir().unwrap();
    let part = part_path("hemisphere.toml");
    let cell = part_path("cells/robowam_part_carried.toml");
    let args = [
        "plan",
        part.to_str().unwrap(),
        "--cell",
        cell.to_str().unwrap(),
        "--points",
        "60",
    ];
    let one = run(&args, dir.path(), 1);
    let two = run(&args, dir.path(), 2);
    assert!(
        one.contains_key(Path::new("joints.csv")),
        "{:?}",
        one.keys()
    );
    assert_same(&one, &two, "plan");
}
