//! The fuzz targets on stable: a seeded, property-based mutation run of the same functions that cargo-fuzz's
//! targets call (`fuzz/fuzz_targets/`, nightly only), so that CI, which runs stable, exercises every target on
//! every change. Each run starts from the seeds the fuzzer's corpora are built from (NIST's I++ DME test files
//! and the committed configs), applies a few random edits (bit flips, byte changes, insertions of the bytes that
//! matter to the parsers, deletions, copies within the input and splices from another seed) and calls the
//! target, which panics on a failed check; proptest then shrinks a failing input to a small one.
//!
//! `write_seed_corpora` (ignored) writes those seeds as cargo-fuzz's corpus folders: `fuzz/seed-corpora.sh`
//! runs it, so that the nightly run and this one start from the same inputs.

use std::path::{Path, PathBuf};

use proptest::prelude::*;
use proptest::sample::Index;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};
use zeroset::api::{to_line, Request, RequestLine};

/// A fuzz target: one input, a panic on a failed check.
type Target = fn(&[u8]);

/// Mutated inputs tried per target: about a second or two each in the test profile on a shared core.
const CASES: u32 = 3000;

/// NIST's I++ DME 1.4 test files: `shared/` sits beside the repository checkout (as for the drivers' golden
/// tests).
fn nist_dir() -> PathBuf {
    let dir = repo("../shared/reference/ippdme-nist-1.4");
    assert!(
        dir.join("README").is_file(),
        "NIST I++ DME test files not found at {}: the `shared` folder must sit beside the repository checkout",
        dir.display()
    );
    dir
}

fn repo(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(path)
}

/// The files in `dir` whose names end in one of `suffixes`, sorted.
fn files(dir: &Path, suffixes: &[&str]) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("reading {}: {e}", dir.display()))
        .map(|entry| entry.expect("directory entry").path())
        .filter(|path| suffixes.iter().any(|s| path.to_string_lossy().ends_with(s)))
        .collect();
    files.sort();
    files
}

/// The wire lines of a NIST .prg or .res file, CR LF included: the file without its message separators
/// (`\\`) and end marker (`:`).
fn nist_lines(path: &Path) -> Vec<Vec<u8>> {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("reading {}: {e}", path.display()));
    bytes
        .split_inclusive(|&b| b == b'\n')
        .filter(|line| !matches!(*line, b"\\\\\r\n" | b":\r\n"))
        .map(<[u8]>::to_vec)
        .collect()
}

/// The chunk byte the codec target reads first: 64-byte reads.
const CODEC_CHUNK: u8 = 64;

/// The seeds of a target, by its name (cargo-fuzz's).
fn seeds(target: &str) -> Vec<Vec<u8>> {
    let seeds: Vec<Vec<u8>> = match target {
        // Each NIST program and response file as one stream, as a machine or a client would send it.
        "codec" => files(&nist_dir(), &[".prg", ".res"])
            .iter()
            .map(|file| {
                let mut stream = vec![CODEC_CHUNK];
                stream.extend(nist_lines(file).concat());
                stream
            })
            .collect(),
        // Every distinct line of NIST's response files, without its CR LF.
        "response" => {
            let mut lines: Vec<Vec<u8>> = files(&nist_dir(), &[".res"])
                .iter()
                .flat_map(|file| nist_lines(file))
                .map(|line| line.strip_suffix(b"\r\n").unwrap_or(&line).to_vec())
                .collect();
            lines.sort();
            lines.dedup();
            lines
        }
        // One line of each request, as the CLI writes it.
        "control_request" => [
            Request::Status,
            Request::Teach {
                part: "propeller".into(),
            },
            Request::Inspect {
                part: "propeller".into(),
                serial: "SN-0042".into(),
            },
            Request::Abort,
            Request::Clear,
            Request::Report {
                serial: "SN-0042".into(),
            },
            Request::Subscribe,
        ]
        .into_iter()
        .map(|request| to_line(&RequestLine::new(request)).into_bytes())
        .collect(),
        "station_config" => read_all(&files(&repo("config"), &[".toml"])),
        "part_config" => read_all(&files(&repo("config/parts"), &[".toml"])),
        other => panic!("no fuzz target named {other}"),
    };
    assert!(!seeds.is_empty(), "no seeds for {target}");
    seeds
}

fn read_all(files: &[PathBuf]) -> Vec<Vec<u8>> {
    files
        .iter()
        .map(|file| {
            std::fs::read(file).unwrap_or_else(|e| panic!("reading {}: {e}", file.display()))
        })
        .collect()
}

/// One edit of an input; positions are fractions of the input's length when the edit is made.
#[derive(Debug, Clone)]
enum Edit {
    FlipBit {
        at: Index,
        bit: u8,
    },
    SetByte {
        at: Index,
        byte: u8,
    },
    Insert {
        at: Index,
        bytes: Vec<u8>,
    },
    Remove {
        at: Index,
        len: usize,
    },
    /// A stretch of the input copied over another place of it (a repeated key, a doubled number).
    Duplicate {
        from: Index,
        to: Index,
        len: usize,
    },
    /// A stretch of another seed inserted.
    Splice {
        seed: Index,
        from: Index,
        at: Index,
        len: usize,
    },
}

/// Bytes that start, end or separate something in one of the parsers: digits and signs of numbers, I++'s
/// separators and markers, line ends, JSON's and TOML's punctuation, and bytes that are not ASCII or not UTF-8.
const TOKENS: &[&[u8]] = &[
    b"0",
    b"9",
    b"-",
    b"+",
    b".",
    b"E",
    b"e999",
    b"1e308",
    b"nan",
    b"inf",
    b"9999999999999999",
    b",",
    b" ",
    b"(",
    b")",
    b"\"",
    b"#",
    b"!",
    b"&",
    b"%",
    b"\r\n",
    b"\n",
    b"\r",
    b"E0000",
    b"{",
    b"}",
    b"[",
    b"]",
    b":",
    b"=",
    b"[[",
    b"]]",
    b"\\",
    b"\x00",
    b"\x7f",
    b"\xc3\xa9",
    b"\xff",
    b"true",
    b"null",
];

fn edit() -> impl Strategy<Value = Edit> {
    let stretch = 1usize..64;
    prop_oneof![
        (any::<Index>(), 0u8..8).prop_map(|(at, bit)| Edit::FlipBit { at, bit }),
        (any::<Index>(), any::<u8>()).prop_map(|(at, byte)| Edit::SetByte { at, byte }),
        (any::<Index>(), prop::sample::select(TOKENS)).prop_map(|(at, token)| Edit::Insert {
            at,
            bytes: token.to_vec()
        }),
        (any::<Index>(), prop::collection::vec(any::<u8>(), 1..8))
            .prop_map(|(at, bytes)| Edit::Insert { at, bytes }),
        (any::<Index>(), stretch.clone()).prop_map(|(at, len)| Edit::Remove { at, len }),
        (any::<Index>(), any::<Index>(), stretch.clone())
            .prop_map(|(from, to, len)| Edit::Duplicate { from, to, len }),
        (any::<Index>(), any::<Index>(), any::<Index>(), stretch).prop_map(
            |(seed, from, at, len)| Edit::Splice {
                seed,
                from,
                at,
                len
            }
        ),
    ]
}

/// `at` as a place in `input`, from 0 to its length (an insertion may go at the end).
fn place(at: &Index, input: &[u8]) -> usize {
    at.index(input.len() + 1)
}

fn apply(input: &mut Vec<u8>, edit: &Edit, seeds: &[Vec<u8>]) {
    match edit {
        Edit::FlipBit { at, bit } if !input.is_empty() => {
            let at = at.index(input.len());
            input[at] ^= 1 << bit;
        }
        Edit::SetByte { at, byte } if !input.is_empty() => {
            let at = at.index(input.len());
            input[at] = *byte;
        }
        Edit::FlipBit { .. } | Edit::SetByte { .. } => {}
        Edit::Insert { at, bytes } => {
            let at = place(at, input);
            input.splice(at..at, bytes.iter().copied());
        }
        Edit::Remove { at, len } => {
            let at = place(at, input);
            input.drain(at..(at + len).min(input.len()));
        }
        Edit::Duplicate { from, to, len } => {
            let from = place(from, input);
            let copied = input[from..(from + len).min(input.len())].to_vec();
            let to = place(to, input);
            input.splice(to..(to + copied.len()).min(input.len()), copied);
        }
        Edit::Splice {
            seed,
            from,
            at,
            len,
        } => {
            let other = &seeds[seed.index(seeds.len())];
            let from = place(from, other);
            let at = place(at, input);
            input.splice(
                at..at,
                other[from..(from + len).min(other.len())].iter().copied(),
            );
        }
    }
}

/// Runs `target` on every seed as it is, then on [`CASES`] mutants, from a fixed random seed so that a
/// failure repeats.
fn mutation_run(name: &str, target: Target) {
    let seeds = seeds(name);
    for seed in &seeds {
        target(seed);
    }
    let config = Config {
        cases: CASES,
        failure_persistence: None,
        ..Config::default()
    };
    let mut runner =
        TestRunner::new_with_rng(config, TestRng::deterministic_rng(RngAlgorithm::ChaCha));
    let mutants = (any::<Index>(), prop::collection::vec(edit(), 1..8));
    let result = runner.run(&mutants, |(seed, edits)| {
        let mut input = seeds[seed.index(seeds.len())].clone();
        for edit in &edits {
            apply(&mut input, edit, &seeds);
        }
        target(&input);
        Ok(())
    });
    if let Err(failure) = result {
        panic!("fuzz target {name} failed: {failure}");
    }
}

#[test]
fn codec_survives_mutated_nist_streams() {
    mutation_run("codec", zeroset_drivers::fuzz::codec);
}

#[test]
fn response_parser_survives_mutated_nist_lines() {
    mutation_run("response", zeroset_drivers::fuzz::response);
}

#[test]
fn control_request_parser_survives_mutated_requests() {
    mutation_run("control_request", zeroset::api::fuzz::control_request);
}

#[test]
fn station_config_loader_survives_mutated_station_files() {
    mutation_run("station_config", zeroset::config::fuzz::station_config);
}

#[test]
fn part_config_loader_survives_mutated_part_files() {
    mutation_run("part_config", zeroset::config::fuzz::part_config);
}

/// The shipped propeller part file with `from` replaced by `to`, as the fuzzer might have edited it.
fn propeller_with(from: &str, to: &str) -> Vec<u8> {
    let text =
        std::fs::read_to_string(repo("config/parts/propeller.toml")).expect("the shipped part");
    assert!(text.contains(from), "the shipped part has no {from:?}");
    text.replacen(from, to, 1).into_bytes()
}

/// Inputs that failed a target once, kept so that they cannot come back. Each was accepted by the part loader
/// and planned into machine coordinates that are infinite, NaN or not a rigid turn.
#[test]
fn part_files_that_once_broke_the_plan_are_refused() {
    for (from, to) in [
        // Instance C turned by 2 * 1e308 degrees: an infinite angle, NaN coordinates.
        ("step_deg = 120.0", "step_deg = 1e308"),
        // A turn about a point at 1e308 mm shifts by more than f64 holds.
        (
            "axis_point_mm = [0.0, 0.0, 0.0]",
            "axis_point_mm = [1e308, 1e308, 1e308]",
        ),
        // A direction whose length overflows normalises to zero: a "rotation" that scales.
        (
            "axis_direction = [0.0, 0.0, 1.0]",
            "axis_direction = [1e308, 0.0, 1e308]",
        ),
    ] {
        zeroset::config::fuzz::part_config(&propeller_with(from, to));
    }
}

/// Writes every target's seeds to `fuzz/corpus/TARGET/`, one file each, named by index.
#[test]
#[ignore = "writes cargo-fuzz's seed corpora; run by fuzz/seed-corpora.sh"]
fn write_seed_corpora() {
    for target in [
        "codec",
        "response",
        "control_request",
        "station_config",
        "part_config",
    ] {
        let dir = repo("fuzz/corpus").join(target);
        std::fs::create_dir_all(&dir).unwrap_or_else(|e| panic!("creating {}: {e}", dir.display()));
        for (index, seed) in seeds(target).iter().enumerate() {
            let file = dir.join(format!("seed-{index:05}"));
            std::fs::write(&file, seed)
                .unwrap_or_else(|e| panic!("writing {}: {e}", file.display()));
        }
    }
}
