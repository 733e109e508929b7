//! The README's commands and the built-in help stay true.

use crate::support::{repo, zeroset, zeroset_ok};

/// The commands of the README's first code block.
fn readme_commands() -> Vec<String> {
    let readme = std::fs::read_to_string(repo().join("README.md")).expect("README.md");
    let block = readme
        .split("```sh\n")
        .nth(1)
        .expect("a sh code block")
        .split("```")
        .next()
        .unwrap();
    block.lines().map(str::to_string).collect()
}

#[test]
fn the_readme_opens_with_the_example_and_the_test_command() {
    let commands = readme_commands();
    assert_eq!(commands.len(), 2, "{commands:?}");
    assert_eq!(commands[1], "cargo test --workspace");
    let ci = std::fs::read_to_string(repo().join(".ci/run")).expect(".ci/run");
    assert!(
        ci.lines().any(|l| l == commands[1]),
        ".ci/run must run the README's test command"
    );
}

#[test]
fn the_readme_example_runs_and_finds_blade_b_0_8_mm_inside() {
    // Run the example's zeroset invocations with the binary under test, in order, as the README chains them.
    let dir = tempfile::tempdir().unwrap();
    let mut last = String::new();
    for invocation in readme_commands()[0].split(" && ") {
        let args: Vec<String> = invocation
            .strip_prefix("cargo run --release -- ")
            .expect("the example runs the zeroset binary")
            .split_whitespace()
            .map(|a| a.replace("/tmp/", &format!("{}/", dir.path().display())))
            .collect();
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        last = zeroset_ok(&args);
    }
    let summary = last
        .lines()
        .find(|l| l.trim_start().starts_with("n = 400, mean "))
        .expect("a summary line");
    let mean: f64 = summary
        .split("mean ")
        .nth(1)
        .unwrap()
        .split(' ')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert!((mean + 0.8).abs() < 0.001, "{summary}");
    assert!(summary.contains(" mm"), "units are stated: {summary}");
}

#[test]
fn help_describes_every_command_with_units() {
    let top = zeroset_ok(&["--help"]);
    assert!(
        top.contains("fit") && top.contains("deviate") && top.contains("sim"),
        "{top}"
    );
    let sim = zeroset_ok(&["sim", "--help"]);
    assert!(
        sim.contains("--config") && sim.contains("--time-scale") && sim.contains("fault"),
        "{sim}"
    );
    let fit = zeroset_ok(&["fit", "ip", "--help"]);
    for option in [
        "--points",
        "--degree",
        "--method",
        "--normals",
        "--stack",
        "--out",
        "mm",
    ] {
        assert!(fit.contains(option), "fit ip --help lacks {option}:\n{fit}");
    }
    let deviate = zeroset_ok(&["deviate", "--help"]);
    for option in [
        "--model",
        "--points",
        "--distance",
        "exact",
        "paper",
        "taubin",
        "mm",
    ] {
        assert!(
            deviate.contains(option),
            "deviate --help lacks {option}:\n{deviate}"
        );
    }
    assert!(!zeroset(&["no-such-command"]).success);
}
