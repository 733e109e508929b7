//! The property of issue 13: wherever along its planned moves a probe stops (the descent, the contact scan, the
//! lift-off, the way out; for a teach also past the last point the machine reported), the way out `zeroset clear`
//! plans from there is clear of the real part, or the station refuses to move. The real part is the simulator's
//! own NACA 4412 ground truth, offset from the taught model by up to 0.5 mm as blades B and C are, so the check
//! does not rest on the model the planner used.

use nalgebra::{Point2, Point3, Vector3};
use rand::{rngs::StdRng, Rng, SeedableRng};
use zeroset_sim::naca::Naca4;

use super::super::*;
use crate::config::Safety;
use crate::geometry::sweep::mesh::MeshPart;
use crate::plan::ProfileKey;
use crate::station::motion::{Scan, ScanMotion};

const SECTION_X_MM: f64 = 300.0;
const BALL_MM: f64 = 1.0;
const INSPECT_MARGIN_MM: f64 = 5.0;
const TEACH_MARGIN_MM: f64 = 5.0;
const CASES: usize = 300;

fn safety() -> Safety {
    Safety {
        clearance_z_mm: 150.0,
        max_ball_radius_mm: 1.5,
        move_margin_mm: 0.5,
    }
}

/// A closed section in the plane x = 300: points (y, z) counter-clockwise, the trailing edge first, with their
/// outward normals from the neighbouring points.
struct Section {
    points: Vec<Point2<f64>>,
    normals: Vec<Vector3<f64>>,
}

impl Section {
    /// NACA 4412 of 100 mm chord, the leading edge at y = -50, `count` points (even), moved `offset_mm` along
    /// its normals (outwards positive).
    fn naca(count: usize, offset_mm: f64) -> Section {
        let naca = Naca4::from_digits("4412", 100.0, true).unwrap();
        let base: Vec<Point2<f64>> = naca
            .points(count)
            .into_iter()
            .map(|[x, z]| Point2::new(x - 50.0, z))
            .collect();
        let n = base.len();
        let normals: Vec<Vector3<f64>> = (0..n)
            .map(|i| {
                let d = base[(i + 1) % n] - base[(i + n - 1) % n];
                // Counter-clockwise: the outside is to the right of the direction of travel.
                Vector3::new(0.0, d.y, -d.x).normalize()
            })
            .collect();
        let points = base
            .iter()
            .zip(&normals)
            .map(|(p, m)| Point2::new(p.x + m.y * offset_mm, p.y + m.z * offset_mm))
            .collect();
        Section { points, normals }
    }

    fn point3(&self, i: usize) -> Point3<f64> {
        Point3::new(SECTION_X_MM, self.points[i].x, self.points[i].y)
    }

    /// The index of the top of the upper surface: the entry of its scans.
    fn top(&self) -> usize {
        (0..self.points.len() / 2)
            .max_by(|&a, &b| self.points[a].y.total_cmp(&self.points[b].y))
            .unwrap()
    }

    /// Signed distance from (y, z) to the section, negative inside.
    fn signed_distance(&self, q: &Point3<f64>) -> f64 {
        let q = Point2::new(q.y, q.z);
        let n = self.points.len();
        let mut least = f64::INFINITY;
        let mut inside = false;
        for i in 0..n {
            let (a, b) = (self.points[i], self.points[(i + 1) % n]);
            let ab = b - a;
            let t = ((q - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0);
            least = least.min((q - (a + ab * t)).norm());
            if (a.y > q.y) != (b.y > q.y) && q.x < a.x + (q.y - a.y) / (b.y - a.y) * ab.x {
                inside = !inside;
            }
        }
        if inside {
            -least
        } else {
            least
        }
    }

    /// The section extruded 40 mm either side of its plane, as a closed mesh (caps in strips between the upper
    /// and the lower surface at the same chord position).
    fn mesh(&self) -> MeshPart {
        let n = self.points.len();
        let mut vertices = Vec::new();
        for x in [SECTION_X_MM - 40.0, SECTION_X_MM + 40.0] {
            vertices.extend(self.points.iter().map(|p| Point3::new(x, p.x, p.y)));
        }
        let mut triangles = Vec::new();
        for i in 0..n {
            let j = (i + 1) % n;
            triangles.push([i, j, n + j]);
            triangles.push([i, n + j, n + i]);
        }
        for i in 0..n / 2 {
            // Upper i, i + 1 and lower n - i, n - i - 1 (index 0 is the trailing edge, n / 2 the leading edge).
            let (u0, u1, l0, l1) = (i, i + 1, (n - i) % n, n - i - 1);
            let mut cap = vec![[u0, l1, u1]];
            if l0 != u0 {
                cap.push([u0, l0, l1]);
            }
            for t in cap {
                if t[0] != t[1] && t[1] != t[2] && t[0] != t[2] {
                    triangles.push(t);
                    triangles.push([n + t[0], n + t[2], n + t[1]]);
                }
            }
        }
        MeshPart::new(vertices.clone(), triangles.clone(), 0.0)
            .or_else(|_| {
                let flipped = triangles.iter().map(|t| [t[0], t[2], t[1]]).collect();
                MeshPart::new(vertices, flipped, 0.0)
            })
            .expect("a closed mesh")
    }

    /// The section as the station knows it from a model: its points and normals, a closed path entered at the top.
    fn path(&self) -> KnownPath {
        let entry = self.top();
        KnownPath {
            surface: (0..self.points.len()).map(|i| self.point3(i)).collect(),
            normals: self.normals.clone(),
            closed: true,
            entry,
        }
    }
}

/// The ball's least clearance from the real part over the straight moves from `from` through `moves`, sampled
/// every 0.02 mm, and over the legs after the first.
fn clearance(real: &Section, from: Point3<f64>, moves: &[Point3<f64>]) -> (f64, f64) {
    let (mut all, mut after_first) = (f64::INFINITY, f64::INFINITY);
    let mut at = from;
    for (leg, to) in moves.iter().enumerate() {
        let steps = ((to - at).norm() / 0.02).ceil().max(1.0) as usize;
        for k in 0..=steps {
            let p = at + (to - at) * (k as f64 / steps as f64);
            let gap = real.signed_distance(&p) - BALL_MM;
            all = all.min(gap);
            if leg > 0 {
                after_first = after_first.min(gap);
            }
        }
        at = *to;
    }
    (all, after_first)
}

/// A point at fraction `t` along the polyline through `points`.
fn along(points: &[Point3<f64>], t: f64) -> Point3<f64> {
    let legs = points.len() - 1;
    let at = t * legs as f64;
    let i = (at.floor() as usize).min(legs - 1);
    points[i] + (points[i + 1] - points[i]) * (at - i as f64)
}

/// Checks one stop: the planned way out is clear of the real part (the ball may start in contact, never go in)
/// and ends at the clearance height, or it is refused. Returns whether it moved.
fn check_stop(
    real: &Section,
    stop: Point3<f64>,
    path: &KnownPath,
    margin: f64,
    model: &EscapeModel,
    what: &str,
) -> bool {
    let start = real.signed_distance(&stop) - BALL_MM;
    match plan_escape(stop, Some((path, margin)), BALL_MM, &safety(), model) {
        Ok(moves) => {
            let (all, after_first) = clearance(real, stop, &moves);
            assert!(
                all >= start.min(0.0) - 1e-6,
                "{what}: from {stop} (clearance {start:.4} mm) the way out {moves:?} brings the ball {all:.4} mm into \
                 the part"
            );
            if moves.len() > 1 {
                assert!(
                    after_first > 0.0,
                    "{what}: from {stop} the way out touches the part after its lift-off ({after_first:.4} mm)"
                );
            }
            let last = moves.last().map_or(stop, |p| *p);
            assert!(
                last.z >= safety().clearance_z_mm - 1e-9,
                "{what}: ends at {last}"
            );
            true
        }
        Err(_) => false,
    }
}

#[test]
fn a_way_out_from_any_stop_along_an_inspection_is_clear_of_the_real_part_or_refused() {
    let model = Section::naca(400, 0.0);
    let escape = EscapeModel {
        paths: Vec::new(),
        part: Some(std::sync::Arc::new(model.mesh())),
        deviation_margin_mm: INSPECT_MARGIN_MM,
    };
    let path = model.path();
    let motion = ScanMotion::plan(
        ProfileKey {
            instance: 1,
            profile: 0,
        },
        "instance B, profile r300".into(),
        Scan::Curve(zeroset_drivers::machine::CurveScan {
            closed: true,
            nominals: Vec::new(),
            max_deviation: 3.0,
            min_radius: 1.0,
            density: zeroset_drivers::machine::Density::AtNominals,
        }),
        path.clone(),
        INSPECT_MARGIN_MM,
        &safety(),
    )
    .unwrap();
    let mut rng = StdRng::seed_from_u64(13);
    let (mut moved, mut cases) = (0, 0);
    for case in 0..CASES {
        // Blade B or C: the real section up to 0.5 mm inside or outside the model.
        let offset = rng.gen_range(-0.5..0.5);
        let real = Section::naca(2000, offset);
        let (what, stop) = match case % 5 {
            0 => ("descent", along(&motion.approach, rng.gen())),
            4 => {
                // The scan's own approach, out along the entry's normal by up to the expected deviation and the
                // search distance (where a surface-not-found leaves the probe).
                let entry = path.entry;
                let out = rng.gen_range(0.0..9.0);
                (
                    "scan approach",
                    path.surface[entry] + path.normals[entry] * (BALL_MM + out),
                )
            }
            1 => {
                // In contact with the real part anywhere round the section.
                let i = rng.gen_range(0..real.points.len());
                let n = real.normals[i];
                ("scan", real.point3(i) + n * BALL_MM)
            }
            2 => {
                let top = real.top();
                let end = real.point3(top) + real.normals[top] * BALL_MM;
                (
                    "lift-off",
                    end + (motion.retract[0] - end) * rng.gen::<f64>(),
                )
            }
            _ => {
                let legs: Vec<Point3<f64>> = motion.retract.clone();
                ("way out", along(&legs, rng.gen()))
            }
        };
        cases += 1;
        moved += usize::from(check_stop(
            &real,
            stop,
            &path,
            INSPECT_MARGIN_MM,
            &escape,
            what,
        ));
    }
    // Refusing everything would pass the property; the planner must get the probe out nearly always.
    eprintln!(
        "inspection: the way out moved the probe from {moved} of {cases} stops, refused the rest"
    );
    assert!(
        moved * 100 >= cases * 95,
        "moved {moved} of {cases} stops; the rest were refused"
    );
}

#[test]
fn a_way_out_from_any_stop_of_a_teach_scan_is_clear_of_the_part_or_refused() {
    // No model yet: the way out knows the start point and the points the machine reported, which lag the probe
    // by up to a data line of ten 1 mm steps.
    let real = Section::naca(1000, 0.0);
    let top = real.top();
    let n = real.points.len();
    let mut rng = StdRng::seed_from_u64(14);
    let (mut moved, mut cases) = (0, 0);
    for _ in 0..CASES {
        // The scan runs from the top towards the trailing edge, round it and along the lower surface (index
        // decreasing from the top through 0 and on from n - 1).
        let reported = rng.gen_range(1..n - 20);
        let unreported = rng.gen_range(0..10);
        let index = |k: usize| (top + n - k % n) % n;
        let mut path = KnownPath {
            surface: vec![real.point3(top)],
            normals: vec![Vector3::new(0.0, 0.0, 1.0)],
            closed: false,
            entry: 0,
        };
        for k in 1..=reported {
            path.surface.push(real.point3(index(k)));
            path.normals.push(real.normals[index(k)]);
        }
        let stopped = index(reported + unreported);
        let stop = real.point3(stopped) + real.normals[stopped] * BALL_MM;
        cases += 1;
        moved += usize::from(check_stop(
            &real,
            stop,
            &path,
            TEACH_MARGIN_MM,
            &EscapeModel::default(),
            "teach scan",
        ));
    }
    eprintln!("teach: the way out moved the probe from {moved} of {cases} stops, refused the rest");
    assert!(
        moved * 100 >= cases * 80,
        "moved {moved} of {cases} stops; the rest were refused"
    );
}
