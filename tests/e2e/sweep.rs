//! The station's clearance check and the simulated CMM agree (issue 6): straight moves past and into the
//! simulated nut are judged by the check, swept against the taught model, then made by the simulator over its
//! pseudo-terminal. Every move the check passes runs clear; every move it finds cutting into the part ends in
//! the simulator's collision error (2504). The planner and the machine share no code: the simulator measures its
//! own analytic nut, the check the mesh of the reference fitted to the master's scans.

use nalgebra::Point3;
use rand::{Rng, SeedableRng};
use zeroset::analysis::Reference;
use zeroset::config::{PartConfig, StationConfig};
use zeroset::geometry::sweep::clearance::check_move;
use zeroset::geometry::sweep::motion::Motion;
use zeroset::geometry::sweep::part::PartDistance;
use zeroset::geometry::sweep::stylus::Stylus;
use zeroset::plan::Plan;
use zeroset::station::clearance::machine_part;
use zeroset_drivers::machine::{Machine, Xyz};

use crate::daemon::Station;
use crate::sim::{quick, Sim};
use crate::support::config;

/// The simulator's Probe1.
const BALL_RADIUS_MM: f64 = 1.0;
/// Travel between moves above the nut's top (25 mm).
const TRAVEL_Z_MM: f64 = 40.0;
/// Moves whose swept ball comes within this of touching, either way, are not judged: the model is the master's
/// fit (2 um) seen through its mesh's chord tolerance (0.15 mm, subtracted by the check).
const UNDECIDED_MM: f64 = 0.3;

fn xyz(p: &Point3<f64>) -> Xyz {
    Xyz::new(p.x, p.y, p.z)
}

#[test]
fn sweep_clearance_check_and_the_simulated_collision_agree() {
    let teacher = Station::start_as("nut.toml", "station-nut.toml");
    let out = teacher.cli_ok(&["teach", "nut"]);
    assert!(out.contains("reference saved"), "{out}");
    let reference = Reference::load(&teacher.reference_of("nut")).expect("the taught reference");
    drop(teacher);
    let station =
        StationConfig::load(config("station-nut.toml").as_ref()).expect("the station file");
    let part = PartConfig::load(config("parts/nut.toml").as_ref()).expect("the part file");
    let plan = Plan::new(&part, station.part_to_machine.isometry());
    let model = machine_part(&plan, &reference).expect("the nut's mesh");
    let stylus = Stylus::new(BALL_RADIUS_MM, 0.6, 30.0).expect("a stylus");

    let mut rng = rand::rngs::StdRng::seed_from_u64(6);
    // Each move with the check's verdict: its clearance (mm), or, when it touches the model, the depth the ball
    // would reach into it (negative).
    let moves: Vec<(Point3<f64>, Point3<f64>, f64)> = (0..40)
        .map(|_| {
            let (a, b): (f64, f64) = (
                rng.gen_range(0.0..std::f64::consts::TAU),
                rng.gen_range(-0.6..0.6),
            );
            let z = rng.gen_range(4.0..21.0);
            let reach = rng.gen_range(30.0..60.0);
            let from = Point3::new(60.0 * a.cos(), 60.0 * a.sin(), z);
            let to = Point3::new(reach * (a + b).cos(), reach * (a + b).sin(), z);
            let clearance = check_move(&stylus, &Motion::line(from, to), &model, 0.0);
            // The check stops at the first contact; how deep the move would go decides whether it is a graze.
            let verdict = match clearance.first_contact_t {
                Some(_) => (0..=2000)
                    .map(|k| {
                        model.distance(&(from + (to - from) * (k as f64 / 2000.0))) - BALL_RADIUS_MM
                    })
                    .fold(f64::INFINITY, f64::min),
                None => clearance.min_distance_mm,
            };
            (from, to, verdict)
        })
        .collect();

    let sim = Sim::start("nut.toml");
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .expect("a runtime");
    let (mut clear, mut collided, mut undecided) = (0, 0, 0);
    runtime.block_on(async {
        let client = sim.client("cmm1", quick());
        client.start_session().await.expect("a session");
        client.home().await.expect("homing");
        client.change_tool("Probe1").await.expect("the tool");
        for (index, (from, to, min_distance)) in moves.iter().enumerate() {
            // To the move's start from above: the nut's top is at 25 mm.
            let here = client.position().await.expect("the position");
            client.go_to(Xyz::new(here.x, here.y, TRAVEL_Z_MM)).await.expect("up");
            client.go_to(Xyz::new(from.x, from.y, TRAVEL_Z_MM)).await.expect("across");
            client.go_to(xyz(from)).await.expect("down outside the nut");
            let made = client.go_to(xyz(to)).await;
            let hit = match &made {
                Ok(()) => false,
                Err(error) if error.device_error().map(|e| e.code()) == Some(2504) => true,
                Err(error) => panic!("move {index}: {error}"),
            };
            if hit {
                client.clear_all_errors().await.expect("ClearAllErrors");
                client.go_to(xyz(from)).await.expect("back out the way it came");
            }
            if min_distance.abs() < UNDECIDED_MM {
                undecided += 1;
                continue;
            }
            assert_eq!(
                hit,
                *min_distance < 0.0,
                "move {index} from {from} to {to}: the check says {min_distance:.3} mm, the simulator {}",
                if hit { "collided" } else { "ran clear" }
            );
            if hit {
                collided += 1;
            } else {
                clear += 1;
            }
        }
    });
    eprintln!("{clear} moves clear, {collided} collided, {undecided} within {UNDECIDED_MM} mm of touching");
    assert!(
        clear >= 5 && collided >= 5 && undecided <= 10,
        "{clear} clear, {collided} collided, {undecided} undecided"
    );
}
