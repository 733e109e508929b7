//! The perspective silhouette of the ball's swept volume (seed 002, Algorithm 1): the envelope's part is the
//! common zero set of F (eq. 1) and G (eq. 2), found by sampling t for seeds, traced numerically, its t-extreme
//! points (eq. 3) located on the way; the end caps (the ball at t = 0 facing backwards, at t = 1 facing
//! forwards) contribute arcs of the ball's own silhouette circle, in closed form. Pieces that share end points
//! form the connected components, drawn as SVG polylines in a perspective view from the eye.
//!
//! Limitation (as in the paper's sampling of the zero set): a loop of the envelope's silhouette that lives
//! entirely between two sampled times (shorter than 1 / SEED_TIMES in t) is not found.

use std::f64::consts::TAU;
use std::fmt::Write;

use nalgebra::{Matrix3, Point3, Vector3};

use super::ball_system::{BallSweep, SilhouetteSystem, SurfaceTime};
use super::charts::SpherePoint;
use super::motion::Motion;
use super::tracer::{correct, distance_to_curve, trace_through, TracedCurve};

/// Times sampled for seeds of the envelope's silhouette.
const SEED_TIMES: usize = 32;
/// Two end points closer than this (mm) are the same point when components are assembled.
const JOIN_TOLERANCE_MM: f64 = 1e-6;

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SilhouetteError {
    #[error("the silhouette needs a smooth motion (a scan's corners are not); split the scan into lines")]
    NotSmooth,
    #[error("the eye is inside the swept volume")]
    EyeInside,
    #[error("the step must be positive, got {0} mm")]
    BadStep(f64),
}

/// Where a piece of silhouette lies on the swept volume's boundary.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PieceKind {
    /// On the envelope: F = G = 0.
    Envelope,
    /// On the ball at t = 0, on its backward-facing half.
    StartCap,
    /// On the ball at t = 1, on its forward-facing half.
    EndCap,
}

#[derive(Debug, Clone)]
pub struct SilhouettePiece {
    pub kind: PieceKind,
    /// Surface-time parameters of the points (body-frame unit normal and t).
    pub params: Vec<SurfaceTime>,
    /// The points in the part's frame (mm).
    pub points: Vec<Point3<f64>>,
    pub closed: bool,
}

/// A t-extreme point (F = G = H = 0): where K^t and L^t touch.
#[derive(Debug, Clone, Copy)]
pub struct TExtreme {
    pub param: SurfaceTime,
    pub point: Point3<f64>,
}

/// One connected component of the silhouette.
#[derive(Debug, Clone)]
pub struct SilhouetteComponent {
    pub pieces: Vec<SilhouettePiece>,
    pub t_extremes: Vec<TExtreme>,
}

/// The silhouette of the ball of radius `radius_mm` swept by `motion`, seen from `eye`, traced with steps of
/// about `step_mm`.
pub fn ball_silhouette(
    motion: &Motion,
    radius_mm: f64,
    eye: Point3<f64>,
    step_mm: f64,
) -> Result<Vec<SilhouetteComponent>, SilhouetteError> {
    if !motion.is_smooth() {
        return Err(SilhouetteError::NotSmooth);
    }
    if step_mm.is_nan() || step_mm <= 0.0 {
        return Err(SilhouetteError::BadStep(step_mm));
    }
    let sweep = BallSweep {
        motion,
        radius_mm,
        eye: Some(eye),
    };
    let system = SilhouetteSystem { sweep: &sweep };
    let scale = radius_mm.max(sweep.speed_bound()).max(1.0);
    let max_steps = (10.0 * (sweep.speed_bound() + TAU * radius_mm) / step_mm) as usize + 100;

    let mut curves: Vec<TracedCurve> = Vec::new();
    for k in 0..=SEED_TIMES {
        let t = k as f64 / SEED_TIMES as f64;
        if sweep.body_eye(t).is_some_and(|p| p.norm() <= radius_mm) {
            return Err(SilhouetteError::EyeInside);
        }
        for seed in seeds_at(&system, t, scale) {
            if curves
                .iter()
                .all(|c| distance_to_curve(&sweep, c, &seed) > step_mm)
            {
                curves.push(trace_through(
                    &sweep, &system, seed, step_mm, max_steps, scale,
                ));
            }
        }
    }

    let mut pieces: Vec<(SilhouettePiece, Vec<TExtreme>)> = curves
        .into_iter()
        .map(|c| {
            let extremes = t_extremes(&sweep, &system, &c, scale);
            (
                piece(&sweep, PieceKind::Envelope, c.points, c.closed),
                extremes,
            )
        })
        .collect();
    for (t, kind) in [(0.0, PieceKind::StartCap), (1.0, PieceKind::EndCap)] {
        for (arc, closed) in cap_arcs(&sweep, t, step_mm) {
            pieces.push((piece(&sweep, kind, arc, closed), Vec::new()));
        }
    }
    Ok(components(pieces))
}

fn piece(
    sweep: &BallSweep<'_>,
    kind: PieceKind,
    params: Vec<SurfaceTime>,
    closed: bool,
) -> SilhouettePiece {
    let points = params.iter().map(|q| sweep.world_point(q)).collect();
    SilhouettePiece {
        kind,
        params,
        points,
        closed,
    }
}

/// Solutions of F = G = 0 at a fixed t: Newton from the 26 directions of a cube's faces, edges and corners.
fn seeds_at(system: &SilhouetteSystem<'_>, t: f64, scale: f64) -> Vec<SurfaceTime> {
    let mut found: Vec<SurfaceTime> = Vec::new();
    for i in -1..=1 {
        for j in -1..=1 {
            for k in -1..=1 {
                if (i, j, k) == (0, 0, 0) {
                    continue;
                }
                let start = SurfaceTime {
                    s: SpherePoint::from_normal(&Vector3::new(i as f64, j as f64, k as f64)),
                    t,
                };
                if let Some(q) = correct(system, start, true, scale) {
                    if found
                        .iter()
                        .all(|f| (f.normal() - q.normal()).norm() > 1e-6)
                    {
                        found.push(q);
                    }
                }
            }
        }
    }
    found
}

/// The t-extreme points along a traced curve: where its t stops increasing or decreasing, refined by Newton's
/// method on F = G = H = 0 (eq. 3), H's gradient by central differences.
fn t_extremes(
    sweep: &BallSweep<'_>,
    system: &SilhouetteSystem<'_>,
    curve: &TracedCurve,
    scale: f64,
) -> Vec<TExtreme> {
    let pts = &curve.points;
    let n = pts.len();
    let count = if curve.closed { n } else { n.saturating_sub(2) };
    let mut out: Vec<TExtreme> = Vec::new();
    for i in 0..count {
        let (a, b, c) = if curve.closed {
            (pts[i], pts[(i + 1) % n], pts[(i + 2) % n])
        } else {
            (pts[i], pts[i + 1], pts[i + 2])
        };
        if (b.t - a.t) * (c.t - b.t) >= 0.0 {
            continue;
        }
        if let Some(q) = refine_t_extreme(sweep, system, b, scale) {
            if out
                .iter()
                .all(|e| (e.param.normal() - q.normal()).norm() + (e.param.t - q.t).abs() > 1e-6)
            {
                out.push(TExtreme {
                    param: q,
                    point: sweep.world_point(&q),
                });
            }
        }
    }
    out
}

fn refine_t_extreme(
    sweep: &BallSweep<'_>,
    system: &SilhouetteSystem<'_>,
    start: SurfaceTime,
    scale: f64,
) -> Option<SurfaceTime> {
    use super::ball_system::CurveSystem;
    const H: f64 = 1e-6;
    let mut q = start;
    for _ in 0..40 {
        let (fg, j) = system.evaluate(&q);
        let h = sweep.t_extremality(&q);
        let mut grad_h = Vector3::zeros();
        for k in 0..3 {
            let mut e = Vector3::zeros();
            e[k] = H;
            grad_h[k] = (sweep.t_extremality(&q.shifted(&e))
                - sweep.t_extremality(&q.shifted(&-e)))
                / (2.0 * H);
        }
        let m = Matrix3::from_rows(&[
            j.row(0).into_owned(),
            j.row(1).into_owned(),
            grad_h.transpose(),
        ]);
        let delta = m.lu().solve(&Vector3::new(fg.x, fg.y, h))?;
        q = q.shifted(&-delta);
        q.s = q.s.rechart();
        if delta.amax() < 1e-14 {
            break;
        }
    }
    let (fg, _) = system.evaluate(&q);
    (fg.amax() <= 1e-10 * scale && (0.0..=1.0).contains(&q.t)).then_some(q)
}

/// Arcs of the ball's own silhouette circle L^t (<p, n> = r) at an end of the motion, restricted to the half that
/// bounds the swept volume: sigma <w, n> >= 0 with sigma = -1 at t = 0 and +1 at t = 1.
/// Each arc comes with whether it is the whole circle (closed, its last point not repeated).
fn cap_arcs(sweep: &BallSweep<'_>, t: f64, step_mm: f64) -> Vec<(Vec<SurfaceTime>, bool)> {
    let r = sweep.radius_mm;
    let p = sweep.body_eye(t).expect("an eye point");
    let w = sweep.body_velocity(t) * if t == 0.0 { -1.0 } else { 1.0 };
    let dist = p.norm();
    let axis = p / dist;
    let (cos_a, sin_a) = (r / dist, (1.0 - (r / dist).powi(2)).sqrt());
    let e1 = axis
        .cross(&Vector3::x())
        .try_normalize(1e-6)
        .unwrap_or_else(|| axis.cross(&Vector3::y()).normalize());
    let e2 = axis.cross(&e1);
    let normal_at = |beta: f64| axis * cos_a + (e1 * beta.cos() + e2 * beta.sin()) * sin_a;
    // sigma <w, n(beta)> = a + b cos(beta) + c sin(beta)
    let (a, b, c) = (w.dot(&axis) * cos_a, w.dot(&e1) * sin_a, w.dot(&e2) * sin_a);
    let amplitude = b.hypot(c);
    let intervals: Vec<(f64, f64, bool)> = if a >= amplitude {
        vec![(0.0, TAU, true)]
    } else if a <= -amplitude {
        Vec::new()
    } else {
        // a + amplitude cos(beta - phi) >= 0 for |beta - phi| <= acos(-a / amplitude).
        let phi = c.atan2(b);
        let half = (-a / amplitude).acos();
        vec![(phi - half, phi + half, false)]
    };
    let circle_step = step_mm / (r * sin_a);
    intervals
        .into_iter()
        .map(|(lo, hi, full)| {
            let count = ((hi - lo) / circle_step).ceil().max(4.0) as usize;
            let last = if full { count - 1 } else { count };
            let arc = (0..=last)
                .map(|i| SurfaceTime {
                    s: SpherePoint::from_normal(&normal_at(
                        lo + (hi - lo) * i as f64 / count as f64,
                    )),
                    t,
                })
                .collect();
            (arc, full)
        })
        .collect()
}

/// Groups pieces into connected components: pieces whose end points coincide belong together.
fn components(pieces: Vec<(SilhouettePiece, Vec<TExtreme>)>) -> Vec<SilhouetteComponent> {
    let n = pieces.len();
    let mut parent: Vec<usize> = (0..n).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    let ends = |p: &SilhouettePiece| -> Vec<Point3<f64>> {
        if p.closed || p.points.is_empty() {
            Vec::new()
        } else {
            vec![p.points[0], p.points[p.points.len() - 1]]
        }
    };
    for i in 0..n {
        for j in i + 1..n {
            let touch = ends(&pieces[i].0).iter().any(|a| {
                ends(&pieces[j].0)
                    .iter()
                    .any(|b| (a - b).norm() < JOIN_TOLERANCE_MM)
            });
            if touch {
                let (ri, rj) = (root(&mut parent, i), root(&mut parent, j));
                parent[ri] = rj;
            }
        }
    }
    let mut groups: Vec<(usize, SilhouetteComponent)> = Vec::new();
    for (i, (piece, extremes)) in pieces.into_iter().enumerate() {
        let r = root(&mut parent, i);
        let at = match groups.iter().position(|(g, _)| *g == r) {
            Some(at) => at,
            None => {
                groups.push((
                    r,
                    SilhouetteComponent {
                        pieces: Vec::new(),
                        t_extremes: Vec::new(),
                    },
                ));
                groups.len() - 1
            }
        };
        groups[at].1.pieces.push(piece);
        groups[at].1.t_extremes.extend(extremes);
    }
    groups.into_iter().map(|(_, c)| c).collect()
}

/// A perspective view: the eye, the point it looks at and the up direction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct View {
    pub eye: Point3<f64>,
    pub target: Point3<f64>,
    pub up: Vector3<f64>,
}

impl View {
    /// Central projection onto the plane at unit distance in front of the eye (image x right, y up).
    pub fn project(&self, p: &Point3<f64>) -> Option<(f64, f64)> {
        let forward = (self.target - self.eye).normalize();
        let right = forward.cross(&self.up).normalize();
        let up = right.cross(&forward);
        let d = p - self.eye;
        let depth = d.dot(&forward);
        (depth > 0.0).then(|| (d.dot(&right) / depth, d.dot(&up) / depth))
    }
}

/// A piece's kind and its points on the image plane.
type ProjectedPiece = (PieceKind, Vec<(f64, f64)>);

/// The components as an SVG document of `size_px` square: one group per component, one polyline per piece
/// (envelope pieces black, cap pieces grey).
pub fn silhouette_svg(components: &[SilhouetteComponent], view: &View, size_px: f64) -> String {
    let projected: Vec<Vec<ProjectedPiece>> = components
        .iter()
        .map(|c| {
            c.pieces
                .iter()
                .map(|p| {
                    let mut pts: Vec<(f64, f64)> =
                        p.points.iter().filter_map(|x| view.project(x)).collect();
                    if p.closed && !pts.is_empty() {
                        pts.push(pts[0]);
                    }
                    (p.kind, pts)
                })
                .collect()
        })
        .collect();
    let all = projected.iter().flatten().flat_map(|(_, pts)| pts.iter());
    let (mut lo, mut hi) = (
        (f64::INFINITY, f64::INFINITY),
        (f64::NEG_INFINITY, f64::NEG_INFINITY),
    );
    for &(x, y) in all {
        lo = (lo.0.min(x), lo.1.min(y));
        hi = (hi.0.max(x), hi.1.max(y));
    }
    let extent = (hi.0 - lo.0).max(hi.1 - lo.1).max(f64::MIN_POSITIVE);
    let margin = 0.05 * size_px;
    let scale = (size_px - 2.0 * margin) / extent;
    // Centred in both directions: the shorter side gets the extra room.
    let left = margin + 0.5 * (extent - (hi.0 - lo.0)) * scale;
    let bottom = margin + 0.5 * (extent - (hi.1 - lo.1)) * scale;
    let mut svg = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{size_px}\" height=\"{size_px}\" viewBox=\"0 0 {size_px} {size_px}\">\n"
    );
    for (i, component) in projected.iter().enumerate() {
        let _ = writeln!(
            svg,
            "<g id=\"component-{i}\" fill=\"none\" stroke-width=\"1\">"
        );
        for (kind, pts) in component {
            let stroke = if *kind == PieceKind::Envelope {
                "black"
            } else {
                "grey"
            };
            let coords: Vec<String> = pts
                .iter()
                .map(|(x, y)| {
                    format!(
                        "{:.3},{:.3}",
                        left + (x - lo.0) * scale,
                        size_px - bottom - (y - lo.1) * scale
                    )
                })
                .collect();
            let _ = writeln!(
                svg,
                "<polyline stroke=\"{stroke}\" points=\"{}\"/>",
                coords.join(" ")
            );
        }
        svg.push_str("</g>\n");
    }
    svg.push_str("</svg>\n");
    svg
}

/// A traced characteristic curve: surface-time parameters, points in the part's frame, whether it closed.
#[derive(Debug, Clone)]
pub struct CharacteristicCurve {
    pub params: Vec<SurfaceTime>,
    pub points: Vec<Point3<f64>>,
    pub closed: bool,
}

/// The characteristic curve K^t of the ball at time t (F = 0 at fixed t), traced numerically from a seed found by
/// Newton's method, as points in the part's frame. The closed form is the great circle perpendicular to the
/// centre's velocity ([`super::envelope`]); this general tracer is what a body without a closed form would use.
pub fn traced_characteristic(
    motion: &Motion,
    radius_mm: f64,
    t: f64,
    step_mm: f64,
) -> Option<CharacteristicCurve> {
    use super::ball_system::CharacteristicAt;
    let sweep = BallSweep {
        motion,
        radius_mm,
        eye: None,
    };
    let system = CharacteristicAt { sweep: &sweep, t };
    let scale = sweep.speed_bound().max(1.0);
    let seed = [
        Vector3::x(),
        Vector3::y(),
        Vector3::z(),
        Vector3::new(1.0, 1.0, 1.0),
    ]
    .iter()
    .find_map(|d| {
        correct(
            &system,
            SurfaceTime {
                s: SpherePoint::from_normal(d),
                t,
            },
            false,
            scale,
        )
    })?;
    let max_steps = (10.0 * TAU * radius_mm / step_mm) as usize + 100;
    let curve = trace_through(&sweep, &system, seed, step_mm, max_steps, scale);
    let points = curve.points.iter().map(|q| sweep.world_point(q)).collect();
    Some(CharacteristicCurve {
        params: curve.points,
        points,
        closed: curve.closed,
    })
}
