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

/// The RMS column of a blade's row in the demo's per-blade table.
fn blade_rms(output: &str, blade: &str) -> f64 {
    // The table's row: the blade's name, then its point count (the live lines name a profile second).
    let row = output
        .lines()
        .find(|l| {
            let mut words = l.split_whitespace();
            words.next() == Some(blade) && words.next().is_some_and(|w| w.parse::<usize>().is_ok())
        })
        .unwrap_or_else(|| panic!("no row for blade {blade}:\n{output}"));
    row.split_whitespace().nth(3).unwrap().parse().unwrap()
}

#[test]
fn the_readme_demo_teaches_and_inspects_the_simulated_propeller() {
    let command = &readme_commands()[0];
    let args: Vec<&str> = command
        .strip_prefix("cargo run --release -- ")
        .expect("the demo runs the zeroset binary")
        .split_whitespace()
        .collect();
    let out = zeroset_ok(&args);
    assert!(out.contains("reference saved"), "{out}");
    assert!(
        out.contains("mean mm") && out.contains("RMS mm"),
        "units are stated:\n{out}"
    );
    // Blade A is the master: it reads the probe's noise. B and C are shifted 0.4 to 1.0 mm.
    assert!(blade_rms(&out, "A") < 0.01, "{out}");
    assert!(
        blade_rms(&out, "B") > 0.3 && blade_rms(&out, "C") > 0.3,
        "{out}"
    );
    let report = out
        .lines()
        .find_map(|l| l.strip_prefix("report: "))
        .expect("the report's folder is printed");
    assert!(
        std::path::Path::new(report).join("report.json").is_file(),
        "{report}"
    );
}

#[test]
fn help_describes_every_command_with_units() {
    let top = zeroset_ok(&["--help"]);
    for command in [
        "fit", "deviate", "sim", "demo", "daemon", "teach", "inspect", "watch", "status", "abort",
        "clear", "report", "mesh", "sweep",
    ] {
        assert!(top.contains(command), "--help lacks {command}:\n{top}");
    }
    let inspect = zeroset_ok(&["inspect", "--help"]);
    assert!(
        inspect.contains("--serial")
            && inspect.contains("--config")
            && inspect.contains("--detach"),
        "{inspect}"
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
    for (command, options) in [
        (
            "mesh",
            &["--model", "--out", "--cell-mm", "--epsilon", "mm"][..],
        ),
        ("sweep", &["--config", "--eye", "--out", "mm"][..]),
    ] {
        let help = zeroset_ok(&[command, "--help"]);
        for option in options {
            assert!(
                help.contains(option),
                "{command} --help lacks {option}:
{help}"
            );
        }
    }
    assert!(!zeroset(&["no-such-command"]).success);
}
