//! The core's decisions phase by phase: inputs in, effects out, no machine or file behind them (the jobs are set
//! up once from the shipped propeller's part file into a temporary folder).

use std::path::PathBuf;

use super::*;
use crate::api::{FaultKind, MachineState, ProfileFit};
use crate::config::StationConfig;
use crate::station::job::prepare;

const MACHINE: &str = "cmm1";

struct Bench {
    core: Core,
    config: StationConfig,
    _data: tempfile::TempDir,
    next_id: RequestId,
}

impl Bench {
    /// A station whose machine its worker has looked at and found ready.
    fn new() -> Bench {
        let mut bench = Bench::unseen();
        bench.core.handle(Input::Seen {
            machine: MACHINE.into(),
        });
        bench
    }

    /// A station whose machine its worker has not looked at yet.
    fn unseen() -> Bench {
        let data = tempfile::tempdir().unwrap();
        let mut config = StationConfig::load(
            &PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("config/station.toml"),
        )
        .unwrap();
        config.folders.data = data.path().to_path_buf();
        Bench {
            core: Core::new("test station".into(), vec![MACHINE.into()], None),
            config,
            _data: data,
            next_id: 0,
        }
    }

    fn request(&mut self, request: Request) -> (RequestId, Vec<Effect>) {
        self.next_id += 1;
        let id = self.next_id;
        (id, self.core.handle(Input::Request { id, request }))
    }

    fn teach_job(&self) -> Box<Job> {
        Box::new(prepare(&self.config, JobKind::Teach, "propeller", None).unwrap())
    }

    /// A teach requested and set up: returns the effects of its start.
    fn start_teach(&mut self) -> Vec<Effect> {
        let (id, effects) = self.request(Request::Teach {
            part: "propeller".into(),
        });
        assert!(
            matches!(
                effects.as_slice(),
                [Effect::Prepare {
                    kind: JobKind::Teach,
                    ..
                }]
            ),
            "a teach is prepared off the decision task, and not answered yet"
        );
        let job = self.teach_job();
        self.core.handle(Input::Prepared {
            id,
            result: Ok(job),
        })
    }

    fn machine(&mut self) -> MachineState {
        let (_, effects) = self.request(Request::Status);
        let status = reply_of(&effects).and_then(|r| match r {
            Reply::Status(status) => Some(status.as_ref().clone()),
            _ => None,
        });
        status.unwrap().machines[0].state.clone()
    }

    fn phase(&self) -> JobPhase {
        self.core.job().unwrap().phase.clone()
    }

    fn scan_ended(&mut self, key: ProfileKey, result: ScanResult) -> Vec<Effect> {
        self.core.handle(Input::ScanEnded {
            machine: MACHINE.into(),
            key,
            result,
        })
    }
}

fn reply_of(effects: &[Effect]) -> Option<&Reply> {
    effects.iter().find_map(|e| match e {
        Effect::Reply { reply, .. } => Some(reply),
        _ => None,
    })
}

fn scanned(effects: &[Effect]) -> Option<ProfileKey> {
    effects.iter().find_map(|e| match e {
        Effect::Scan { motion, .. } => Some(motion.key),
        _ => None,
    })
}

/// Whether any effect would move, clear or stop a machine.
fn touches_a_machine(effects: &[Effect]) -> bool {
    effects.iter().any(|e| {
        matches!(
            e,
            Effect::Scan { .. } | Effect::Clear { .. } | Effect::Abort { .. }
        )
    })
}

fn estop() -> WorkerError {
    WorkerError {
        kind: FaultKind::Device {
            severity: 3,
            code: 500,
        },
        message: "machine cmm1: the machine raised error 0500 (severity 3): Emergency stop".into(),
    }
}

fn published(effects: &[Effect], wanted: impl Fn(&Event) -> bool) -> bool {
    effects
        .iter()
        .any(|e| matches!(e, Effect::Publish(event) if wanted(event)))
}

#[test]
fn a_job_is_set_up_off_the_decision_task_and_status_answers_meanwhile() {
    let mut bench = Bench::new();
    let (id, effects) = bench.request(Request::Teach {
        part: "propeller".into(),
    });
    assert!(matches!(effects.as_slice(), [Effect::Prepare { .. }]));
    // While it is being set up: status says so, a second job is refused.
    let (_, effects) = bench.request(Request::Status);
    let Some(Reply::Status(status)) = reply_of(&effects) else {
        panic!("status answered at once");
    };
    assert_eq!(status.preparing.as_ref().unwrap().part, "propeller");
    let (_, effects) = bench.request(Request::Teach {
        part: "propeller".into(),
    });
    assert!(
        matches!(reply_of(&effects), Some(Reply::Error { message }) if message.contains("being set up"))
    );
    // Set up: started, its pipeline opened, and the first scan given to the machine by its planned motion.
    let job = bench.teach_job();
    let first_motion = job.motions.values().next().unwrap().clone();
    let effects = bench.core.handle(Input::Prepared {
        id,
        result: Ok(job),
    });
    assert!(matches!(reply_of(&effects), Some(Reply::Started { .. })));
    assert!(effects.iter().any(|e| matches!(e, Effect::StartPipeline)));
    let motion = effects
        .iter()
        .find_map(|e| match e {
            Effect::Scan {
                motion, machine, ..
            } if machine == MACHINE => Some(motion),
            _ => None,
        })
        .unwrap();
    assert_eq!(**motion, first_motion, "the very motion planned at set-up");
    assert!(matches!(bench.machine(), MachineState::Scanning { .. }));
}

#[test]
fn a_job_that_cannot_be_set_up_is_refused_with_its_reason() {
    let mut bench = Bench::new();
    let (id, _) = bench.request(Request::Teach {
        part: "propeller".into(),
    });
    let effects = bench.core.handle(Input::Prepared {
        id,
        result: Err(JobError("part propeller: no such file".into())),
    });
    assert!(
        matches!(reply_of(&effects), Some(Reply::Error { message }) if message.contains("no such file"))
    );
    assert!(!touches_a_machine(&effects));
    // And the station is free for the next.
    let (_, effects) = bench.request(Request::Teach {
        part: "propeller".into(),
    });
    assert!(matches!(effects.as_slice(), [Effect::Prepare { .. }]));
}

#[test]
fn an_estop_stops_the_job_and_abort_ends_it_without_clearing_or_moving_a_machine() {
    let mut bench = Bench::new();
    let effects = bench.start_teach();
    let key = scanned(&effects).unwrap();
    let effects = bench.scan_ended(key, Err(estop()));
    assert!(
        !touches_a_machine(&effects),
        "nothing moves after an E-stop"
    );
    assert!(published(&effects, |e| matches!(
        e,
        Event::JobStopped { .. }
    )));
    assert!(matches!(bench.phase(), JobPhase::Stopped { .. }));
    let MachineState::LockedOut { fault } = bench.machine() else {
        panic!("locked out");
    };
    assert_eq!(
        fault.kind,
        FaultKind::Device {
            severity: 3,
            code: 500
        }
    );

    let (_, effects) = bench.request(Request::Abort);
    assert!(
        !touches_a_machine(&effects),
        "abort after an E-stop neither clears nor moves"
    );
    assert!(
        matches!(reply_of(&effects), Some(Reply::Done { message }) if message.contains("zeroset clear"))
    );
    assert!(published(&effects, |e| matches!(
        e,
        Event::JobAborted { .. }
    )));
    assert!(effects.iter().any(
        |e| matches!(e, Effect::SaveRecord { record, .. } if record.state == JobState::Aborted)
    ));
    assert_eq!(bench.phase(), JobPhase::Aborted);
    assert!(
        matches!(bench.machine(), MachineState::LockedOut { .. }),
        "still locked out"
    );

    // No new job while the machine is locked out; `zeroset clear` lifts it.
    let (_, effects) = bench.request(Request::Teach {
        part: "propeller".into(),
    });
    assert!(
        matches!(reply_of(&effects), Some(Reply::Error { message }) if message.contains("locked out") && message.contains("zeroset clear"))
    );
    assert!(!effects.iter().any(|e| matches!(e, Effect::Prepare { .. })));
    let (_, effects) = bench.request(Request::Clear);
    assert!(effects
        .iter()
        .any(|e| matches!(e, Effect::Clear { machine, .. } if machine == MACHINE)));
    assert!(
        reply_of(&effects).is_none(),
        "answered once the machine has cleared"
    );
    let effects = bench.core.handle(Input::Cleared {
        machine: MACHINE.into(),
        result: Ok(()),
    });
    assert!(
        matches!(reply_of(&effects), Some(Reply::Done { message }) if message == "machines clear")
    );
    assert_eq!(bench.machine(), MachineState::Idle);
}

#[test]
fn abort_while_scanning_stops_the_machine_and_leaves_it_locked_out() {
    let mut bench = Bench::new();
    let key = scanned(&bench.start_teach()).unwrap();
    let (_, effects) = bench.request(Request::Abort);
    let aborts: Vec<&Effect> = effects
        .iter()
        .filter(|e| matches!(e, Effect::Abort { .. }))
        .collect();
    assert_eq!(aborts.len(), 1);
    assert!(!effects
        .iter()
        .any(|e| matches!(e, Effect::Clear { .. } | Effect::Scan { .. })));
    assert_eq!(bench.phase(), JobPhase::Aborting);
    // Status and a second abort answer at once while the machine stops.
    assert!(matches!(bench.machine(), MachineState::Scanning { .. }));
    let (_, effects) = bench.request(Request::Abort);
    assert!(
        matches!(reply_of(&effects), Some(Reply::Error { message }) if message.contains("already"))
    );
    // The machine's scan ends with "transaction aborted": the job is over, the machine stays locked out.
    let aborted = WorkerError {
        kind: FaultKind::Device {
            severity: 2,
            code: 6,
        },
        message: "machine cmm1: ScanOnCurve: transaction aborted".into(),
    };
    let effects = bench.scan_ended(key, Err(aborted));
    assert!(
        !touches_a_machine(&effects),
        "no clear, no move after an abort"
    );
    assert!(published(&effects, |e| matches!(
        e,
        Event::JobAborted { .. }
    )));
    let MachineState::LockedOut { fault } = bench.machine() else {
        panic!("locked out");
    };
    assert_eq!(fault.kind, FaultKind::Aborted);
}

#[test]
fn clear_resumes_a_stopped_job_where_it_stopped_and_the_job_then_finishes() {
    let mut bench = Bench::new();
    let first = scanned(&bench.start_teach()).unwrap();
    let job_id = bench.core.job().unwrap().info.id.clone();
    let total = bench.core.job().unwrap().total;
    bench.scan_ended(first, Err(estop()));
    // A clear while running is refused; while stopped it clears, then resumes.
    let (_, effects) = bench.request(Request::Clear);
    assert!(effects.iter().any(|e| matches!(e, Effect::Clear { .. })));
    let effects = bench.core.handle(Input::Cleared {
        machine: MACHINE.into(),
        result: Ok(()),
    });
    assert!(
        matches!(reply_of(&effects), Some(Reply::Done { message }) if message.contains("continues"))
    );
    assert!(effects.iter().any(|e| matches!(e, Effect::StartPipeline)));
    assert!(published(&effects, |e| matches!(
        e,
        Event::JobResumed { .. }
    )));
    let effects = bench.core.handle(Input::EarlierAnalysisEnded {
        job: job_id.clone(),
        result: Ok(()),
    });
    assert_eq!(
        scanned(&effects),
        Some(first),
        "the cut profile is scanned again"
    );
    let (_, refused) = bench.request(Request::Clear);
    assert!(
        matches!(reply_of(&refused), Some(Reply::Error { message }) if message.contains("nothing to clear"))
    );

    let mut key = first;
    let mut finishes = 0;
    for done in 1..=total {
        let stored = bench.core.handle(Input::Stored {
            job: job_id.clone(),
            key,
            result: Ok(()),
        });
        assert!(stored.is_empty(), "a profile counts done when stored");
        let effects = bench.scan_ended(key, Ok(()));
        finishes += effects
            .iter()
            .filter(|e| matches!(e, Effect::Finish))
            .count();
        match scanned(&effects) {
            Some(next) => key = next,
            None => assert_eq!(done, total, "scans go on until every profile is done"),
        }
    }
    assert_eq!(finishes, 1);
    assert_eq!(bench.phase(), JobPhase::Finishing);
    let (_, effects) = bench.request(Request::Abort);
    assert!(matches!(reply_of(&effects), Some(Reply::Error { .. })));
    let effects = bench.core.handle(Input::Finished {
        job: job_id,
        result: Ok(Outcome::Taught {
            path: "reference.json".into(),
            profiles: vec![ProfileFit {
                profile: "r100".into(),
                points: 391,
                rms_mm: Some(0.002),
                max_mm: None,
                doubts: Vec::new(),
            }],
        }),
    });
    assert!(published(&effects, |e| matches!(
        e,
        Event::ReferenceSaved { .. }
    )));
    assert!(effects.iter().any(
        |e| matches!(e, Effect::SaveRecord { record, .. } if record.state == JobState::Finished)
    ));
    assert_eq!(bench.phase(), JobPhase::Finished);
}

#[test]
fn a_failed_finish_stops_the_job_and_clear_finishes_it_from_its_scans() {
    let mut bench = Bench::new();
    let first = scanned(&bench.start_teach()).unwrap();
    let job_id = bench.core.job().unwrap().info.id.clone();
    let total = bench.core.job().unwrap().total;
    let mut key = first;
    for _ in 0..total {
        bench.core.handle(Input::Stored {
            job: job_id.clone(),
            key,
            result: Ok(()),
        });
        if let Some(next) = scanned(&bench.scan_ended(key, Ok(()))) {
            key = next;
        }
    }
    assert_eq!(bench.phase(), JobPhase::Finishing);
    let effects = bench.core.handle(Input::Finished {
        job: job_id.clone(),
        result: Err("cannot create reports/propeller: Not a directory".into()),
    });
    assert!(published(
        &effects,
        |e| matches!(e, Event::JobStopped { next_step, .. } if next_step.contains("nothing is scanned again"))
    ));
    assert!(matches!(bench.phase(), JobPhase::Stopped { .. }));
    assert!(
        !effects
            .iter()
            .any(|e| matches!(e, Effect::SaveRecord { .. })),
        "the job stays open on disk"
    );
    bench.request(Request::Clear);
    let effects = bench.core.handle(Input::Cleared {
        machine: MACHINE.into(),
        result: Ok(()),
    });
    assert_eq!(scanned(&effects), None, "no profile is scanned again");
    assert_eq!(
        effects
            .iter()
            .filter(|e| matches!(e, Effect::Finish))
            .count(),
        1,
        "finished again from the scans on disk"
    );
}

#[test]
fn a_job_aborted_while_being_set_up_never_starts() {
    let mut bench = Bench::new();
    let (id, _) = bench.request(Request::Teach {
        part: "propeller".into(),
    });
    let (_, effects) = bench.request(Request::Abort);
    assert!(
        matches!(reply_of(&effects), Some(Reply::Done { message }) if message.contains("will not start"))
    );
    let job = bench.teach_job();
    let effects = bench.core.handle(Input::Prepared {
        id,
        result: Ok(job),
    });
    assert!(
        matches!(reply_of(&effects), Some(Reply::Error { message }) if message.contains("aborted before it started"))
    );
    assert!(!touches_a_machine(&effects));
    assert!(!effects.iter().any(|e| matches!(e, Effect::StartPipeline)));
    assert_eq!(bench.phase(), JobPhase::Aborted);
}

#[test]
fn a_profile_that_cannot_be_stored_stops_the_job_naming_the_machine_that_scanned_it() {
    let mut bench = Bench::new();
    let key = scanned(&bench.start_teach()).unwrap();
    let job_id = bench.core.job().unwrap().info.id.clone();
    let effects = bench.core.handle(Input::Stored {
        job: job_id,
        key,
        result: Err("No space left on device".into()),
    });
    assert!(published(
        &effects,
        |e| matches!(e, Event::JobStopped { reason, machine: Some(m), scan: Some(_), .. }
            if reason.contains("No space") && m == MACHINE)
    ));
    // The scan itself ended well: the machine is free, but nothing is dispatched to a stopped job.
    let effects = bench.scan_ended(key, Ok(()));
    assert!(!touches_a_machine(&effects));
    assert_eq!(bench.machine(), MachineState::Idle);
}

#[test]
fn a_failed_clear_keeps_the_machine_locked_out_and_says_why() {
    let mut bench = Bench::new();
    let key = scanned(&bench.start_teach()).unwrap();
    bench.scan_ended(key, Err(estop()));
    bench.request(Request::Clear);
    let effects = bench.core.handle(Input::Cleared {
        machine: MACHINE.into(),
        result: Err(WorkerError {
            kind: FaultKind::Refused,
            message: "machine cmm1: the way out is not clear; jog the probe".into(),
        }),
    });
    assert!(
        matches!(reply_of(&effects), Some(Reply::Error { message }) if message.contains("jog"))
    );
    assert!(!touches_a_machine(&effects));
    let MachineState::LockedOut { fault } = bench.machine() else {
        panic!("still locked out");
    };
    assert_eq!(fault.kind, FaultKind::Refused);
    assert!(matches!(bench.phase(), JobPhase::Stopped { .. }));
}

#[test]
fn a_scan_with_a_hole_is_scanned_again_once_and_a_second_hole_stops_the_job() {
    let mut bench = Bench::new();
    let key = scanned(&bench.start_teach()).unwrap();
    let gap = || {
        WorkerError {
        kind: FaultKind::Gap,
        message: "machine cmm1: the scan of instance A, profile r100 is not whole: a gap of 10.0 mm after point 40"
            .into(),
    }
    };
    let effects = bench.scan_ended(key, Err(gap()));
    assert!(published(
        &effects,
        |e| matches!(e, Event::ProfileRescanned { reason, .. } if reason.contains("10.0 mm"))
    ));
    assert_eq!(
        scanned(&effects),
        Some(key),
        "the same profile, again, at once"
    );
    assert!(effects
        .iter()
        .any(|e| matches!(e, Effect::SaveRecord { record, .. } if record.rescans.len() == 1)));
    assert_eq!(bench.phase(), JobPhase::Running);
    let effects = bench.scan_ended(key, Err(gap()));
    assert!(!touches_a_machine(&effects));
    assert!(published(
        &effects,
        |e| matches!(e, Event::JobStopped { reason, .. } if reason.contains("again after a rescan"))
    ));
    assert_eq!(
        bench.machine(),
        MachineState::Idle,
        "a hole is no fault of the machine"
    );
    assert_eq!(bench.core.job().unwrap().record.rescans.len(), 2);
}

#[test]
fn a_profile_stored_after_its_machine_failed_on_the_way_out_is_not_scanned_again() {
    let mut bench = Bench::new();
    let key = scanned(&bench.start_teach()).unwrap();
    let job_id = bench.core.job().unwrap().info.id.clone();
    // The scan's points all came; the lift-off collided; the recorder stores the scan after the failure.
    let collision = WorkerError {
        kind: FaultKind::Device {
            severity: 3,
            code: 2504,
        },
        message: "machine cmm1: GoTo: collision".into(),
    };
    bench.scan_ended(key, Err(collision));
    bench.request(Request::Clear);
    let effects = bench.core.handle(Input::Cleared {
        machine: MACHINE.into(),
        result: Ok(()),
    });
    assert!(effects.iter().any(|e| matches!(e, Effect::StartPipeline)));
    assert_eq!(
        scanned(&effects),
        None,
        "no scan while the analysis from before the stop may still store one"
    );
    // Its recorder stores the scan only now (its disk was slow), then that analysis ends.
    let effects = bench.core.handle(Input::Stored {
        job: job_id.clone(),
        key,
        result: Ok(()),
    });
    assert_eq!(scanned(&effects), None);
    let effects = bench.core.handle(Input::EarlierAnalysisEnded {
        job: job_id,
        result: Ok(()),
    });
    let next = scanned(&effects).expect("the job continues");
    assert_ne!(next, key, "the stored profile is not scanned again");
}

#[test]
fn an_analysis_from_before_the_stop_that_does_not_end_stops_the_resumed_job_before_any_scan() {
    let mut bench = Bench::new();
    let key = scanned(&bench.start_teach()).unwrap();
    let job_id = bench.core.job().unwrap().info.id.clone();
    bench.scan_ended(key, Err(estop()));
    bench.request(Request::Clear);
    bench.core.handle(Input::Cleared {
        machine: MACHINE.into(),
        result: Ok(()),
    });
    let effects = bench.core.handle(Input::EarlierAnalysisEnded {
        job: job_id.clone(),
        result: Err("it was still storing scans after 30 s".into()),
    });
    assert_eq!(scanned(&effects), None);
    assert!(published(&effects, |e| matches!(
        e,
        Event::JobStopped { reason, next_step, .. }
            if reason.contains("still storing scans after 30 s") && next_step.contains("zeroset clear")
    )));
    // A second end of it (a late answer) changes nothing; the next clear resumes and waits again.
    let effects = bench.core.handle(Input::EarlierAnalysisEnded {
        job: job_id.clone(),
        result: Ok(()),
    });
    assert_eq!(scanned(&effects), None);
    bench.request(Request::Clear);
    let effects = bench.core.handle(Input::Cleared {
        machine: MACHINE.into(),
        result: Ok(()),
    });
    assert_eq!(scanned(&effects), None);
    let effects = bench.core.handle(Input::EarlierAnalysisEnded {
        job: job_id,
        result: Ok(()),
    });
    assert_eq!(
        scanned(&effects),
        Some(key),
        "the cut profile is scanned again"
    );
}

#[test]
fn after_a_restart_with_a_job_open_the_machines_are_locked_out_until_clear() {
    let mut bench = Bench::new();
    let job = bench.teach_job();
    bench.core = Core::new("test station".into(), vec![MACHINE.into()], Some(*job));
    assert!(matches!(bench.machine(), MachineState::LockedOut { .. }));
    // Aborting the reopened job does not free the machine: a new job still waits for `zeroset clear`.
    bench.request(Request::Abort);
    let (_, effects) = bench.request(Request::Teach {
        part: "propeller".into(),
    });
    assert!(
        matches!(reply_of(&effects), Some(Reply::Error { message }) if message.contains("zeroset clear"))
    );
}

#[test]
fn abort_stops_a_machine_that_is_leaving_the_part_after_a_clear() {
    let mut bench = Bench::new();
    let key = scanned(&bench.start_teach()).unwrap();
    bench.scan_ended(key, Err(estop()));
    bench.request(Request::Clear);
    assert_eq!(bench.machine(), MachineState::Clearing);
    let (_, effects) = bench.request(Request::Abort);
    assert!(effects
        .iter()
        .any(|e| matches!(e, Effect::Abort { machine } if machine == MACHINE)));
    assert!(!effects
        .iter()
        .any(|e| matches!(e, Effect::Clear { .. } | Effect::Scan { .. })));
}

#[test]
fn a_fault_seen_on_an_idle_machine_locks_it_out_and_no_job_starts_until_a_clear() {
    let mut bench = Bench::new();
    let lost = WorkerError {
        kind: FaultKind::Transport,
        message: "machine cmm1: its line was lost while idle (the line closed)".into(),
    };
    let effects = bench.core.handle(Input::Observed {
        machine: MACHINE.into(),
        fault: lost.clone(),
    });
    assert!(
        !touches_a_machine(&effects),
        "a fault never moves a machine"
    );
    let MachineState::LockedOut { fault } = bench.machine() else {
        panic!("locked out, not idle: {:?}", bench.machine());
    };
    assert_eq!(fault, lost.fault());
    assert!(bench
        .machine()
        .to_string()
        .starts_with("locked out (disconnected)"));
    let (_, effects) = bench.request(Request::Teach {
        part: "propeller".into(),
    });
    assert!(
        matches!(reply_of(&effects), Some(Reply::Error { message }) if message.contains("cmm1") && message.contains("zeroset clear")),
        "no job on a machine whose line is gone"
    );
    bench.request(Request::Clear);
    bench.core.handle(Input::Cleared {
        machine: MACHINE.into(),
        result: Ok(()),
    });
    assert_eq!(bench.machine(), MachineState::Idle);
}

#[test]
fn a_machine_not_yet_looked_at_is_not_called_idle_and_takes_a_job_s_scans_only_once_seen() {
    let mut bench = Bench::unseen();
    assert_eq!(bench.machine(), MachineState::Unseen);
    assert!(bench.machine().to_string().starts_with("not seen yet"));
    // A job may start, but nothing is sent to a machine whose state is not known.
    let effects = bench.start_teach();
    assert_eq!(scanned(&effects), None);
    assert_eq!(bench.phase(), JobPhase::Running);
    // The first look finds it ready: the job's first scan goes out.
    let effects = bench.core.handle(Input::Seen {
        machine: MACHINE.into(),
    });
    assert!(scanned(&effects).is_some());
    assert!(matches!(bench.machine(), MachineState::Scanning { .. }));
    // A late "seen" changes nothing.
    bench.core.handle(Input::Seen {
        machine: MACHINE.into(),
    });
    assert!(matches!(bench.machine(), MachineState::Scanning { .. }));
}

#[test]
fn a_machine_found_stopped_at_its_first_look_is_locked_out_and_a_job_waiting_for_it_stops() {
    let mut bench = Bench::unseen();
    bench.start_teach();
    let effects = bench.core.handle(Input::Observed {
        machine: MACHINE.into(),
        fault: estop(),
    });
    assert!(!touches_a_machine(&effects));
    assert!(matches!(bench.machine(), MachineState::LockedOut { .. }));
    assert!(matches!(bench.phase(), JobPhase::Stopped { .. }));
    // The stop names the profile the machine would have scanned first.
    let first = bench.core.job().unwrap().plan.nearest(
        &bench.core.job().unwrap().remaining,
        Point3::origin(),
        |key| bench.core.job().unwrap().scan_start(key),
    );
    let first = scan_ref(
        &bench.core.job().unwrap().plan,
        bench.core.job().unwrap().remaining[first.unwrap()],
    );
    assert!(published(
        &effects,
        |e| matches!(e, Event::JobStopped { scan: Some(scan), reason, .. }
        if *scan == first && reason.contains(&format!("its next scan: instance {} profile {}", first.instance, first.profile)))
    ));
    // Being seen afterwards does not lift the lockout: only a clear does.
    bench.core.handle(Input::Seen {
        machine: MACHINE.into(),
    });
    assert!(matches!(bench.machine(), MachineState::LockedOut { .. }));
}

#[test]
fn a_fault_seen_on_a_machine_idle_between_scans_stops_the_job_naming_its_last_scan() {
    // Every profile of a teach scanned, their files not yet written: the machine is idle, the job still runs.
    let mut bench = Bench::new();
    let mut next = scanned(&bench.start_teach());
    let mut last = None;
    while let Some(key) = next {
        last = Some(key);
        next = scanned(&bench.scan_ended(key, Ok(())));
    }
    let last = scan_ref(&bench.core.job().unwrap().plan, last.unwrap());
    assert_eq!(bench.machine(), MachineState::Idle);
    assert_eq!(bench.phase(), JobPhase::Running);
    let effects = bench.core.handle(Input::Observed {
        machine: MACHINE.into(),
        fault: estop(),
    });
    assert!(!touches_a_machine(&effects));
    assert!(published(
        &effects,
        |e| matches!(e, Event::JobStopped { machine: Some(m), scan: Some(scan), reason, next_step, .. }
        if m == MACHINE && *scan == last && reason.contains("part propeller")
            && reason.contains(&format!("its last scan: instance {} profile {}", last.instance, last.profile))
            && next_step.contains("zeroset clear"))
    ));
}

#[test]
fn a_fault_seen_while_a_machine_scans_is_left_to_the_scan_order() {
    let mut bench = Bench::new();
    let key = scanned(&bench.start_teach()).unwrap();
    let effects = bench.core.handle(Input::Observed {
        machine: MACHINE.into(),
        fault: estop(),
    });
    assert!(effects.is_empty(), "the order's end reports it");
    assert!(matches!(bench.machine(), MachineState::Scanning { .. }));
    assert_eq!(bench.phase(), JobPhase::Running);
    bench.scan_ended(key, Err(estop()));
    assert!(matches!(bench.machine(), MachineState::LockedOut { .. }));
    assert!(matches!(bench.phase(), JobPhase::Stopped { .. }));
}
