//! The edge-aware model's accuracy figures of BENCHMARKS.md (issue 15): NACA 2412, 4412, 6412 and 0006 sections
//! with sharp trailing edges at 100 and 250 mm chord, 400 points with 2 um of Gaussian noise along the normal, over
//! 20 noise draws each. Each draw is fitted face by face (`fit ip`'s default, degrees chosen by held-out
//! points) and as one degree-8 polynomial (`--edges none --degree 8`). For each: the largest distance of the true
//! section (20 000 points, cosine-spaced, so dense at the edges) to the model over all draws, the largest within 1%
//! of chord of the leading and of the trailing edge, the worst RMS, and the spread over draws (at each true point, the largest less the
//! smallest signed distance over the draws, at worst).
//!
//!     cargo run --release --example faces_accuracy [-- DRAWS [FIRST_DRAW [DEGREE|auto [SECTIONS [CHORDS]]]]]
//!
//! The draws are seeded FIRST_DRAW (0 unless given) onwards; DEGREE fixes every face's degree instead of choosing
//! it by held-out points; SECTIONS (e.g. 9322,7606) and CHORDS (mm, e.g. 100,250) replace the four sections and
//! two chords. Each draw is also fitted with no face split where its polynomial does not follow it ("faces, none
//! split"), as before stop 53.

use nalgebra::Vector2;
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use zeroset::geometry::distance::ExactDistance;
use zeroset::geometry::faces::{fit_faces, FacesFitOptions};
use zeroset::geometry::fit3l::{fit_ip, FitMethod, FitOptions};
use zeroset::geometry::normals::ordered_profile_normals;
use zeroset::geometry::sampling::ZeroSetSamples;
use zeroset_sim::naca::Naca4;

const SECTIONS: [&str; 4] = ["2412", "4412", "6412", "0006"];
const CHORDS_MM: [f64; 2] = [100.0, 250.0];
const POINTS: usize = 400;
const SIGMA_MM: f64 = 0.002;

/// Signed distances of the truth to each draw's model, one row per draw, with the draws' seeds.
struct Campaign {
    rows: Vec<Vec<f64>>,
    seeds: Vec<u64>,
}

impl Campaign {
    fn summary(&self, truth: &[Vector2<f64>], chord: f64) -> String {
        let worst_where = |near: &dyn Fn(&Vector2<f64>) -> bool| {
            self.rows
                .iter()
                .flat_map(|row| row.iter().zip(truth).filter(|(_, p)| near(p)))
                .fold(0.0f64, |m, (d, _)| m.max(d.abs()))
        };
        let worst = worst_where(&|_| true);
        let row_worst = |row: &Vec<f64>| row.iter().fold(0.0f64, |m, d| m.max(d.abs()));
        let worst_seed = self
            .rows
            .iter()
            .zip(&self.seeds)
            .max_by(|a, b| row_worst(a.0).total_cmp(&row_worst(b.0)))
            .map_or(0, |(_, seed)| *seed);
        let worst_at_nose = worst_where(&|p| p.x < 0.01 * chord);
        let worst_at_tail = worst_where(&|p| p.x > 0.99 * chord);
        let worst_rms = self
            .rows
            .iter()
            .map(|row| (row.iter().map(|d| d * d).sum::<f64>() / row.len() as f64).sqrt())
            .fold(0.0, f64::max);
        let spread = (0..truth.len())
            .map(|i| {
                let (lo, hi) = self
                    .rows
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), row| {
                        (lo.min(row[i]), hi.max(row[i]))
                    });
                hi - lo
            })
            .fold(0.0, f64::max);
        format!(
            "{:>8.1} (draw {worst_seed}) | {:>8.1} | {:>8.1} | {:>6.2} | {:>8.1}",
            worst * 1000.0,
            worst_at_nose * 1000.0,
            worst_at_tail * 1000.0,
            worst_rms * 1000.0,
            spread * 1000.0
        )
    }
}

fn main() {
    let draws: u64 = std::env::args()
        .nth(1)
        .map_or(20, |a| a.parse().expect("a number of draws"));
    let first_draw: u64 = std::env::args()
        .nth(2)
        .map_or(0, |a| a.parse().expect("the first draw's seed"));
    let degree: Option<usize> = std::env::args()
        .nth(3)
        .filter(|a| a != "auto")
        .map(|a| a.parse().expect("a degree for every face, or auto"));
    let sections: Vec<String> = std::env::args().nth(4).map_or_else(
        || SECTIONS.map(String::from).to_vec(),
        |a| a.split(',').map(String::from).collect(),
    );
    let chords: Vec<f64> = std::env::args().nth(5).map_or(CHORDS_MM.to_vec(), |a| {
        a.split(',')
            .map(|c| c.parse().expect("chords in mm"))
            .collect()
    });
    println!("{draws} draws of {POINTS} points (seeds {first_draw} to {}), sigma {} um; distances of the true section to the model, um", first_draw + draws - 1, SIGMA_MM * 1000.0);
    println!();
    println!("| section | chord (mm) | model | max (its draw) | max within 1% of chord of the leading edge | of the trailing edge | worst RMS | spread over draws | faces' edge off the true edge: RMS, most inward | faces' degrees |");
    println!("|---|---|---|---|---|---|---|---|---|---|");
    for digits in &sections {
        for &chord in &chords {
            let foil = Naca4::from_digits(digits, chord, true).expect("digits");
            let truth: Vec<Vector2<f64>> =
                foil.points(20_000).into_iter().map(Vector2::from).collect();
            let clean: Vec<Vector2<f64>> =
                foil.points(POINTS).into_iter().map(Vector2::from).collect();
            let normals = ordered_profile_normals(&clean);
            let mut faces = Campaign {
                rows: Vec::new(),
                seeds: Vec::new(),
            };
            let mut unsplit = Campaign {
                rows: Vec::new(),
                seeds: Vec::new(),
            };
            let mut single = Campaign {
                rows: Vec::new(),
                seeds: Vec::new(),
            };
            let mut degrees = std::collections::BTreeMap::<String, usize>::new();
            // How far the faces' sharp edge lies from the true one along the chord, mm (- inward).
            let mut edge_off = Vec::new();
            for draw in first_draw..first_draw + draws {
                let mut rng = rand::rngs::StdRng::seed_from_u64(draw);
                let noise = Normal::new(0.0, SIGMA_MM).expect("sigma");
                let measured: Vec<Vector2<f64>> = clean
                    .iter()
                    .zip(&normals)
                    .map(|(p, n)| p + n * noise.sample(&mut rng))
                    .collect();
                let options = FacesFitOptions {
                    degree,
                    method: FitMethod::Orthogonal,
                    split_unfollowed: true,
                };
                let fitted = fit_faces(&measured, &options)
                    .expect("the faces fit")
                    .expect("a sharp trailing edge");
                let chosen: Vec<String> = fitted
                    .faces
                    .iter()
                    .map(|f| f.model.degree().to_string())
                    .collect();
                *degrees.entry(chosen.join("+")).or_default() += 1;
                let edge = fitted
                    .model
                    .joins()
                    .iter()
                    .find(|join| join.sharp)
                    .expect("the sharp trailing edge's join");
                edge_off.push(edge.point[0] - chord);
                let three = fit_faces(
                    &measured,
                    &FacesFitOptions {
                        split_unfollowed: false,
                        ..options
                    },
                )
                .expect("the faces fit")
                .expect("a sharp trailing edge");
                unsplit.rows.push(
                    truth
                        .iter()
                        .map(|p| three.model.foot(p).expect("a foot").distance)
                        .collect(),
                );
                faces.seeds.push(draw);
                unsplit.seeds.push(draw);
                single.seeds.push(draw);
                faces.rows.push(
                    truth
                        .iter()
                        .map(|p| fitted.model.foot(p).expect("a foot").distance)
                        .collect(),
                );
                let one = fit_ip(
                    &measured,
                    &ordered_profile_normals(&measured),
                    &FitOptions::new(8, FitMethod::Orthogonal),
                )
                .expect("the single fit");
                let samples = ZeroSetSamples::new(&one.model, &one.domain.scaled(2.0), 1024);
                let exact = ExactDistance::new(&one.model, &samples);
                // A true point with no foot on the polynomial's zero set (it has none near) counts as infinitely far.
                single.rows.push(
                    exact
                        .feet_along_scan(&truth)
                        .into_iter()
                        .map(|f| f.map_or(f64::INFINITY, |f| f.distance))
                        .collect(),
                );
                eprint!(".");
            }
            eprintln!(" NACA {digits} at {chord} mm");
            let degrees: Vec<String> = degrees.iter().map(|(d, n)| format!("{d} x{n}")).collect();
            let edge_rms =
                (edge_off.iter().map(|d| d * d).sum::<f64>() / edge_off.len() as f64).sqrt();
            let most_inward = edge_off.iter().copied().fold(0.0, f64::min);
            println!(
                "| NACA {digits} | {chord} | faces | {} | {:.2}, {:+.2} | {} |",
                faces.summary(&truth, chord),
                edge_rms * 1000.0,
                most_inward * 1000.0,
                degrees.join(", ")
            );
            println!(
                "| NACA {digits} | {chord} | faces, none split | {} | | |",
                unsplit.summary(&truth, chord)
            );
            println!(
                "| NACA {digits} | {chord} | one polynomial, degree 8 | {} | | |",
                single.summary(&truth, chord)
            );
        }
    }
}
