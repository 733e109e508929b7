//! The starts of one supershape's recovery: where Levenberg-Marquardt begins, from each axis guess of
//! `symmetry`. The radial cost has local minima in the turn about the axis and in the exponents, so the starts
//! cover both: the guess's two turns with exponents that suit each, a start read from the points' middle section,
//! and meridians round, boxy and read from the points.

use nalgebra::{Point2, Point3, Rotation3, Vector3};

use super::model::{self, Candidate, Frame, PARAMS};
use super::symmetry::AxisGuess;
use crate::geometry::supershape::formula::Superformula;
use crate::geometry::supershape::prism::fit_prism_section_from_turns;

/// The start exponents n1 = n2 = n3 of r1 for the guess's two turns (see `symmetry::AxisGuess::starts`), and
/// those of r2.
const LOBED_STARTS: [f64; 2] = [1.2, 4.0];
const MERIDIAN_STARTS: [f64; 2] = [2.0, 4.0];

/// The middle section's fit and the meridian's reading use at most this many points (evenly taken).
const SECTION_POINTS: usize = 200;

/// Where a start puts the supershape and r1, before its meridian is chosen.
struct LobedStart {
    rotation: Rotation3<f64>,
    centre: Vector3<f64>,
    sizes: [f64; 3],
    r1: [f64; 3],
}

/// The starts from one axis guess, each with whether each of its symmetry numbers was read from the points:
/// - the section start: the superformula fitted to the outline of the points' middle slab across the axis (a 2-D
///   fit, cheap and with its own starts: `prism::fit_prism_section`) gives r1's exponents, turn, centre and size;
/// - the guess's two turns, each with the exponents that put a lobe's maximum where that turn expects it (n < 2: in
///   the middle of a side, n > 2: at a corner);
///
/// each with a round and a boxy meridian and one read from the points, for every latitude symmetry worth trying.
pub(super) fn of(
    points: &[Point3<f64>],
    guess: &AxisGuess,
    given: Option<[u32; 2]>,
) -> Vec<(Candidate, [bool; 2])> {
    let mut latitudes = vec![guess.symmetry[1]];
    // A meridian's lobes are read from few points; the transparent 4 is tried beside them.
    if given.is_none() && guess.symmetry[1] != 4 {
        latitudes.push(4);
    }
    let mut lobed: Vec<LobedStart> = guess
        .starts
        .iter()
        .zip(LOBED_STARTS)
        .map(|(start, n)| LobedStart {
            rotation: *start,
            centre: guess.centre.coords,
            sizes: guess.half_extents,
            r1: [n; 3],
        })
        .collect();
    if let Some(section) = middle_section(points, guess) {
        lobed.push(section);
    }
    let mut starts = Vec::new();
    for &m2 in &latitudes {
        for start in &lobed {
            let meridian_read = meridian_exponents(points, start, guess.symmetry[0], m2);
            for meridian in MERIDIAN_STARTS.iter().map(|n| [*n; 3]).chain(meridian_read) {
                let mut params = [0.0; PARAMS];
                params[..3].copy_from_slice(start.centre.as_slice());
                params[6..9].copy_from_slice(&start.sizes.map(f64::ln));
                params[9..12].copy_from_slice(&start.r1.map(model::exponent_parameter));
                params[12..].copy_from_slice(&meridian.map(model::exponent_parameter));
                let read = [
                    given.is_none() && guess.detected[0],
                    given.is_none() && guess.detected[1] && m2 == guess.symmetry[1],
                ];
                starts.push((
                    Candidate {
                        frame: Frame {
                            symmetry: [guess.symmetry[0], m2],
                            start: start.rotation,
                        },
                        params,
                    },
                    read,
                ));
            }
        }
    }
    starts
}

/// Starts with other latitude symmetry numbers m2 from a fitted candidate: its centre, turn, sizes and r1 kept,
/// r2 round, boxy and read from the points for each m2 of `latitudes` other than its own. The meridian's lobes
/// are read from few points near two planes and often missed (a misread m2 was half of the seeded misses), while
/// r1 is usually right by then; trying every likely m2 from the fitted r1 is cheaper than from every start.
pub(super) fn other_latitudes(
    points: &[Point3<f64>],
    fitted: &Candidate,
    latitudes: &[u32],
) -> Vec<Candidate> {
    let exponents = fitted.exponents();
    let start = LobedStart {
        rotation: fitted.rotation(),
        centre: Vector3::new(fitted.params[0], fitted.params[1], fitted.params[2]),
        sizes: fitted.sizes(),
        r1: [exponents[0], exponents[1], exponents[2]],
    };
    let [m1, own] = fitted.frame.symmetry;
    latitudes
        .iter()
        .filter(|&&m2| m2 != own)
        .flat_map(|&m2| {
            let read = meridian_exponents(points, &start, m1, m2);
            MERIDIAN_STARTS
                .iter()
                .map(|n| [*n; 3])
                .chain(read)
                .map(move |meridian| {
                    let mut params = fitted.params;
                    params[12..].copy_from_slice(&meridian.map(model::exponent_parameter));
                    Candidate {
                        frame: Frame {
                            symmetry: [m1, m2],
                            start: fitted.frame.start,
                        },
                        params,
                    }
                })
        })
        .collect()
}

/// Starts with other symmetry numbers m1 from a fitted candidate: for each m1 of `counts` other than its own,
/// its centre, axis, sizes and r2 kept, and r1 as the axis guesses' lobed starts (`LOBED_STARTS`) at the two
/// turns about the axis where a lobe's maximum may sit (0 and half a lobe, pi / m1). A section's lobes are misread
/// where its outline is nearly round or its lobes are weak (3 read as 6, 8 as 4 in the seeded cases), while the
/// axis is usually right.
pub(super) fn other_sections(fitted: &Candidate, counts: &[u32]) -> Vec<Candidate> {
    let [own, m2] = fitted.frame.symmetry;
    let rotation = fitted.rotation();
    counts
        .iter()
        .filter(|&&m1| m1 != own)
        .flat_map(|&m1| {
            [0.0, std::f64::consts::PI / f64::from(m1)]
                .into_iter()
                .flat_map(move |turn| {
                    LOBED_STARTS.iter().map(move |&n| {
                        let mut params = fitted.params;
                        params[3..6].fill(0.0);
                        params[9..12].fill(model::exponent_parameter(n));
                        Candidate {
                            frame: Frame {
                                symmetry: [m1, m2],
                                start: rotation
                                    * Rotation3::from_axis_angle(&Vector3::z_axis(), turn),
                            },
                            params,
                        }
                    })
                })
        })
        .collect()
}

/// r2's exponents read from the points for a start: each point in the start's frame gives, through eq. 8 with the
/// start's r1 and sizes, its latitude phi and the radius r2(phi) it asks for; the exponents of a coarse grid (n1 from
/// 1 to 16, n2 and n3 from 0.7 to 12, on up to `SECTION_POINTS` points) that best give those radii. A meridian's two flanks
/// often differ (n2 != n3), which starts with equal exponents do not reach.
fn meridian_exponents(
    points: &[Point3<f64>],
    start: &LobedStart,
    m1: u32,
    m2: u32,
) -> Option<[f64; 3]> {
    let [n1, n2, n3] = start.r1;
    let r1 = Superformula::new(f64::from(m1), n1, n2, n3, 1.0, 1.0).ok()?;
    let sizes = start.sizes;
    let step = points.len().div_ceil(SECTION_POINTS);
    let samples: Vec<(f64, f64)> = points
        .iter()
        .step_by(step)
        .map(|p| {
            let local = start.rotation.inverse() * (p.coords - start.centre);
            let u = Vector3::new(local.x / sizes[0], local.y / sizes[1], local.z / sizes[2]);
            let radius1 = r1.radius(u.y.atan2(u.x));
            let rho = u.x.hypot(u.y) / radius1;
            ((u.z * radius1).atan2(u.x.hypot(u.y)), rho.hypot(u.z))
        })
        .collect();
    const N1: [f64; 5] = [1.0, 2.0, 4.0, 8.0, 16.0];
    const N23: [f64; 5] = [0.7, 1.5, 3.0, 6.0, 12.0];
    N1.iter()
        .flat_map(|&n1| {
            N23.iter()
                .flat_map(move |&n2| N23.iter().map(move |&n3| [n1, n2, n3]))
        })
        .map(|n| {
            let r2 = Superformula {
                m: f64::from(m2),
                n1: n[0],
                n2: n[1],
                n3: n[2],
                a: 1.0,
                b: 1.0,
            };
            let misfit: f64 = samples
                .iter()
                .map(|(phi, r)| (r - r2.radius(*phi)).powi(2))
                .sum();
            (misfit, n)
        })
        .filter(|(misfit, _)| misfit.is_finite())
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, n)| n)
}

/// The section start of `of`: start frame, centre, sizes and r1's exponents from a superformula fitted to the
/// points within 15% of the half height of the guess's middle plane. `None` when too few points lie there or the
/// outline does not fit.
fn middle_section(points: &[Point3<f64>], guess: &AxisGuess) -> Option<LobedStart> {
    let frame = guess.starts[0];
    let band = 0.15 * guess.half_extents[2];
    let slab: Vec<Point2<f64>> = points
        .iter()
        .map(|p| frame.inverse() * (p - guess.centre))
        .filter(|local| local.z.abs() < band)
        .map(|local| Point2::new(local.x, local.y))
        .collect();
    // The lobes' phase is known: the section is fitted from the guess's two turns (in its first start's frame).
    let m = guess.symmetry[0] as usize;
    let turns = [0.0, std::f64::consts::PI / m as f64];
    let step = slab.len().div_ceil(SECTION_POINTS);
    let thinned: Vec<Point2<f64>> = slab.into_iter().step_by(step).collect();
    let section = fit_prism_section_from_turns(&thinned, m, &turns).ok()?;
    let turned = frame * Rotation3::from_axis_angle(&Vector3::z_axis(), section.turn);
    let centre =
        guess.centre.coords + frame * Vector3::new(section.centre.x, section.centre.y, 0.0);
    let f = section.formula;
    (f.n1 > model::SMALLEST_EXPONENT
        && f.n2 > model::SMALLEST_EXPONENT
        && f.n3 > model::SMALLEST_EXPONENT)
        .then_some(LobedStart {
            rotation: turned,
            centre,
            sizes: [section.size_mm, section.size_mm, guess.half_extents[2]],
            r1: [f.n1, f.n2, f.n3],
        })
}
