//! The seeded fault campaign (see campaign/), 100 faults: every fault kind at random moments of inspections,
//! cleared as an operator would, each job checked. `cargo bench --bench fault_campaign -- --faults 1000` runs
//! the long one.

use crate::campaign::{run, Kind, Options};

#[test]
fn a_hundred_seeded_faults_lose_no_point_and_move_nothing_before_a_clear() {
    let tally = run(&Options {
        faults: 100,
        seed: 7,
    });
    let summary = tally.summary();
    eprintln!("{summary}");
    assert_eq!(tally.injected_total(), 100, "{summary}");
    // The campaign did what it says: every kind went in, and the faults that stop a machine did stop one.
    for (kind, n) in &tally.injected {
        assert!(*n > 0, "{kind:?} never injected:\n{summary}");
    }
    assert_eq!(tally.injected.len(), 9, "{summary}");
    // Each fault the machine marks in its transcript took a motion at least once (a delay leaves no mark; a
    // killed daemon is not the machine's), so every fault path was driven, not only armed.
    for kind in tally.injected.keys() {
        if !matches!(kind, Kind::Delay | Kind::KillDaemon) {
            assert!(
                tally.fired.get(kind).is_some_and(|n| *n > 0),
                "{kind:?} never fired:\n{summary}"
            );
        }
    }
    assert!(tally.stops.values().sum::<usize>() > 0, "{summary}");
    assert!(tally.jobs_finished > 0, "{summary}");
    assert!(tally.violations.is_empty(), "{summary}");
}
