//! Probe-radius compensation of a section scan: from the ball centres a CMM reports, in scan order, to the points
//! of the section the ball touched.
//!
//! The ball centre path of a section scan is the boundary of the volume the ball sweeps; the surface is the
//! envelope of the moving ball (seed 002, eq. 1: the moving body touches the envelope along its characteristic,
//! where its velocity has no component along its normal). Compensation is the inverse problem: given the centre
//! path `c(s)` (arc length `s`) and the radius, find the characteristic. In the section plane the ball is a circle
//! of radius `rho = r / cos(tilt)` (the plane cuts a ball whose contact lies `tilt` out of the plane; see below),
//! and eq. 1 for the family of circles `|X - c(s)| = rho(s)` reads `(X - c) . T = -rho rho'`, which gives
//!
//! ```text
//!     X = c - rho (rho' T + sqrt(1 - rho'^2) N)
//! ```
//!
//! with `T` the unit tangent and `N` the unit normal of the centre path pointing away from the material. For a
//! constant tilt (`rho' = 0`) it is the familiar `X = c - rho N`.
//!
//! Sign convention for curvature: `kappa` is signed with respect to that outward normal `N`, positive where the path
//! bends towards `N`, that is where the surface is concave as the ball sees it (inside a bore), negative where it is
//! convex (outside a boss). A surface of curvature `kappa_s` has a centre path of curvature
//! `kappa_c = kappa_s / (1 - rho kappa_s)`, so `1 - rho kappa_s = 1 / (1 + rho kappa_c)`:
//!
//! - `1 - rho kappa_s <= 0`, the surface more concave than the ball: the ball touches two points at once, the centre
//!   path has a corner and the contact jumps from one wall to the other. A sampled path only approaches that limit
//!   (its local fit turns the corner into a tight concave bend), so points are flagged
//!   [`Cusp::ConcaveBeyondBall`] where `1 - rho kappa_s <= concave_margin`.
//! - `1 + rho kappa_c < 0`, a centre path bending convexly tighter than the ball: no surface has it as offset
//!   (inverting it gives the offset curve's swallowtail, contacts running backwards). A ball rolling round a sharp
//!   edge has `1 + rho kappa_c = 0` exactly, so noise makes it slightly negative there: flagged
//!   [`Cusp::TighterThanBall`] only beyond `convex_tolerance`.
//!
//! Flagged points are still compensated along the machine's reported normal (nothing measured is dropped); the
//! flag says their contact is not to be trusted.
//!
//! The local fit: at each point, a least-squares quartic `y(x)` through the 2 K + 1 = 9 centres around it, in a frame
//! along the central-difference chord (a moving least-squares fit, not an interpolation, so noise is averaged). Why
//! a quartic over nine: the contact error is `r` times the normal's angle error, so 0.01 um with a 1 mm ball asks
//! for 1e-5 rad. A parabola's slope at the point is off by a term in `y''' h^2`, the quartic's by one in
//! `y^(5) h^4`: fitted by parabolas, the noise-free ellipse and NACA 0012 of the tests are off by 0.45 um and
//! 0.27 um, by quartics less than 0.01 um. The price is noise: with 2 um on each centre the quartic's slope has a standard deviation of
//! 0.34 sigma / h (a parabola's 0.13 sigma / h), which moves the contact along the surface by `r` times that but
//! off it only by `r` times its square over two. Nine points leave four degrees of freedom, so the fit's residual
//! tells a window the quartic cannot follow (a corner, sampling too coarse for the curvature) from noise. Such a window, bending convexly, falls back to the reported normal (sound there: the
//! ball rolls round an edge and the machine's normal points at it); bending concavely, and turning so from its
//! first centre to its last, it is flagged as a cusp.
//!
//! The tilt (3-D case): a section scan keeps the ball centre in the plane, but where the surface leans along the
//! plane's normal `w` the contact lies `r n.w` out of the plane. The out-of-plane component comes from the
//! machine's reported normal: the only source available live, since neighbouring sections are scanned later or on
//! another machine; its in-plane part only orients `N`, so its noise does not enter the in-plane direction. Sliding
//! the contact along the surface back into the plane (along the surface's steepest direction with respect to `w`,
//! exact where the surface is straight along that direction) moves it to `c - r / cos(tilt) N_plane`: the section
//! point is where a circle of radius `rho = r / cos(tilt)` about the centre touches the section curve.
//!
//! The roll: where the ball rolls round an edge (sharp, or round with a radius up to a quarter of the ball's), its
//! centres lie on one circle, and the contact comes from that circle, fitted to the roll's centres up to the
//! look-ahead, instead of the quartic (see `roll` for why the quartic fails there).
//!
//! Streaming: a point is compensated once the K = 4 points after it have arrived (the first points of a roll that
//! starts in small steps wait longer, until the roll shows where its edge is: see [`ROLL_REACH_AHEAD`]). The first
//! and last K points of an open path have no symmetric window and use the reported normal, as do points where the
//! fit cannot work. Until then a point has a provisional compensation, from the window that ends at it ([`Compensator::preview`]): a
//! machine sends its points in lines of several, so the last K of a line would otherwise wait a whole line for
//! their look-ahead, and the live deviation with them.

mod roll;

use nalgebra::{Point3, SMatrix, SVector, Unit, Vector2, Vector3};

use roll::{roll_through, RollSample, RollThrough, REACH_BACK};

/// Points on each side of the one being compensated: the look-ahead, in points.
pub const LOOK_AHEAD: usize = 4;

/// The most points a roll's first points may wait for, beyond which they take the quartic. A roll that starts in
/// small steps (the ball turning 2 to 5 deg per point onto a blade's trailing edge, as a scan planned on the
/// nominal does round a section turned from it) has not turned far enough within the look-ahead for its circle to
/// place the edge along the face: the sharp edge's circle over 16 deg of centres puts it within about 9 um (one
/// sigma at 2 um noise), and the quartic, whose window straddles the roll's start, 20 um proud of it. Those points
/// wait until the roll has turned through enough, as long as its centres stay on one circle.
const ROLL_REACH_AHEAD: usize = 24;

/// Points in a fitting window.
const WINDOW: usize = 2 * LOOK_AHEAD + 1;

/// Centres before a point that its compensation sees: the quartic's half window, and the centres before it that a
/// roll round an edge may reach back to.
const BEHIND: usize = LOOK_AHEAD + REACH_BACK;

/// Samples kept: those a point's compensation sees behind it, the point, and the most it may wait for.
const HISTORY: usize = BEHIND + 1 + ROLL_REACH_AHEAD;

/// Coefficients of the quartic.
const TERMS: usize = 5;

/// The smallest residual scale a fit is allowed (mm): noise-free paths fit to round-off, and a threshold of zero
/// would call every window unresolved.
const RESIDUAL_FLOOR_MM: f64 = 1e-4;

/// Residuals beyond this many noise sigmas mean the quartic cannot follow the window. With four degrees of freedom
/// an honest window exceeds it with probability 3e-7 (chi-square, 36 > 4 degrees).
const RESIDUAL_SIGMAS: f64 = 3.0;

/// A roll's edge whose radius is under this is sharp: its contacts, spread over its round, are all within this of
/// its apex (a sharp edge's circle has radius 0, one fitted with its radius reads 0 within a few microns).
const SHARP_EDGE_RADIUS_MM: f64 = 0.005;

/// A reported normal whose part in the section plane is shorter than this cannot orient the path's normal (the
/// surface lies nearly in the section plane, which a section scan cannot follow).
const MIN_IN_PLANE: f64 = 0.1;

/// How the compensation of one scan is tuned.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CompensationSettings {
    /// The probe ball's radius, mm.
    pub ball_radius_mm: f64,
    /// The machine's noise on each centre coordinate (one sigma, mm): sets how far a fit's residual may go before
    /// the window counts as unresolved.
    pub noise_sigma_mm: f64,
    /// Flag a point as [`Cusp::ConcaveBeyondBall`] where `1 - rho kappa_s` is at most this.
    pub concave_margin: f64,
    /// Flag a point as [`Cusp::TighterThanBall`] where `1 + rho kappa_c` is below minus this.
    pub convex_tolerance: f64,
}

impl CompensationSettings {
    /// Defaults for a ball of `ball_radius_mm` on a machine of 2 um noise.
    ///
    /// `concave_margin` 0.2 flags surfaces whose concave radius is within 1.25 times the ball's and passes wider
    /// fillets (a 2 mm bore with a 1 mm ball, `1 - r kappa_s = 0.5`, is fitted exactly). A sharper corner, which
    /// the fit smooths over its window, shows as a residual the quartic cannot explain ([`Cusp::UnresolvedConcave`]).
    /// `convex_tolerance` 0.25: a ball rolling round a sharp edge (`1 + r kappa_c = 0`) with 2 um noise at 0.1 mm
    /// spacing stays inside it (the rolling-edge test).
    pub fn new(ball_radius_mm: f64) -> Self {
        CompensationSettings {
            ball_radius_mm,
            noise_sigma_mm: 0.002,
            concave_margin: 0.2,
            convex_tolerance: 0.25,
        }
    }
}

/// Why a point's contact was not trusted.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Cusp {
    /// The surface is (nearly) more concave than the ball, `1 - rho kappa_s` at most the margin (the value given).
    ConcaveBeyondBall { one_minus_rho_kappa: f64 },
    /// The centre path bends convexly tighter than the ball, `1 + rho kappa_c` (given) below minus the tolerance.
    TighterThanBall { one_plus_rho_kappa: f64 },
    /// The window bends concavely and the quartic cannot follow it (residual, mm): a corner of the centre path
    /// sampled too coarsely to tell how sharp it is.
    UnresolvedConcave { residual_mm: f64 },
}

/// Why the machine's reported normal was used.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Fallback {
    /// The first or last points of an open path, or a path too short for a window.
    PathEnd,
    /// The window bends convexly and the quartic cannot follow it, or its centres do not run along one direction
    /// (a path turning by more than a right angle within the window, or repeated centres).
    Unresolved,
    /// The reported normal lies (nearly) along the section plane's normal and cannot orient the path's normal.
    NormalOutOfPlane,
}

/// How a point was compensated.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Method {
    /// From the centre path's local fit; the section's curvature there (1/mm, signed as in the module comment:
    /// concave positive).
    PathFit { surface_curvature: f64 },
    /// From the circle of the centres of a roll round an edge (see `roll`); the edge's radius, mm (about 0 at a
    /// sharp edge, within the noise either way).
    Roll { edge_radius_mm: f64 },
    /// Along the machine's reported normal, slid into the plane.
    Reported(Fallback),
    /// Along the machine's reported normal, and flagged: the point is kept but its contact is not trusted.
    Flagged(Cusp),
}

/// One compensated point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Compensated {
    /// Its index in the scan, from 0.
    pub index: usize,
    /// The section point: the contact slid along the surface into the plane of the ball centre.
    pub surface: Point3<f64>,
    /// The surface's outward unit normal there (3-D: its out-of-plane part from the reported normal).
    pub normal: Vector3<f64>,
    pub method: Method,
}

impl Compensated {
    /// Whether the point's contact is flagged as not to be trusted (keep it, leave it out of statistics).
    pub fn is_flagged(&self) -> bool {
        matches!(self.method, Method::Flagged(_))
    }

    /// Whether the point is a contact of the ball rolling round a sharp edge (its radius under
    /// [`SHARP_EDGE_RADIUS_MM`]): one of several estimates of the edge's apex.
    pub fn is_on_a_sharp_edge(&self) -> bool {
        matches!(self.method, Method::Roll { edge_radius_mm } if edge_radius_mm.abs() < SHARP_EDGE_RADIUS_MM)
    }
}

/// A ball centre and the normal reported with it.
#[derive(Debug, Clone, Copy)]
struct Sample {
    centre: Point3<f64>,
    /// Unit, or NaN for a zero reported normal.
    normal: Vector3<f64>,
    /// The radius of the ball's circle in the section plane, `r / cos(tilt)`; NaN where the tilt is too steep.
    rho: f64,
}

/// The compensation of one section scan, fed point by point.
pub struct Compensator {
    settings: CompensationSettings,
    plane_normal: Unit<Vector3<f64>>,
    /// The last up to `HISTORY` samples, oldest first.
    recent: Vec<Sample>,
    /// Samples received so far.
    received: usize,
    /// The next point to compensate: every point before it is out.
    next: usize,
    /// The point waiting for its roll and the look-ahead up to which its centres were all too short a roll
    /// (the same centres say the same, so they are not asked again).
    waiting_roll: Option<(usize, usize)>,
}

impl Compensator {
    /// For a scan whose ball centres lie in planes of normal `plane_normal` (any length).
    pub fn new(settings: CompensationSettings, plane_normal: Vector3<f64>) -> Self {
        Compensator {
            settings,
            plane_normal: Unit::new_normalize(plane_normal),
            recent: Vec::with_capacity(HISTORY),
            received: 0,
            next: 0,
            waiting_roll: None,
        }
    }

    /// Takes the next ball centre and reported normal; returns the points now compensated, in scan order: none
    /// while the look-ahead fills, then one per point, except that the first points of a roll round an edge may
    /// wait for up to [`ROLL_REACH_AHEAD`] points and then come out together.
    pub fn push(&mut self, centre: Point3<f64>, reported_normal: Vector3<f64>) -> Vec<Compensated> {
        let sample = self.sample(centre, reported_normal);
        if self.recent.len() == HISTORY {
            self.recent.remove(0);
        }
        self.recent.push(sample);
        self.received += 1;
        let newest = self.received - 1;
        if newest < LOOK_AHEAD {
            // The path's start: no points behind it. Compensated at once, so the live delay stays one window.
            self.next = self.received;
            return vec![self.reported(newest, &sample, Method::Reported(Fallback::PathEnd))];
        }
        let mut out = Vec::new();
        while self.next + LOOK_AHEAD <= newest {
            let Some(point) = self.settled(self.next, true) else {
                break;
            };
            out.push(point);
            self.next += 1;
        }
        out
    }

    /// The point `index` compensated from the samples kept, or `None` if `may_wait` and its roll is too short
    /// yet to say where the edge is.
    fn settled(&mut self, index: usize, may_wait: bool) -> Option<Compensated> {
        let oldest = self.received - self.recent.len();
        let at = index - oldest;
        let from = at.saturating_sub(BEHIND);
        let known_short = match self.waiting_roll {
            Some((waiting, ahead)) if waiting == index => ahead,
            _ => 0,
        };
        let compensated = self.compensated(
            index,
            &self.recent[from..],
            at - from,
            known_short,
            may_wait,
        );
        self.waiting_roll = match compensated {
            None => Some((index, self.received - 1 - index)),
            Some(_) => None,
        };
        compensated
    }

    /// The newest point's provisional compensation, while its final one waits for the look-ahead: from the
    /// quartic of the window that ends at it, evaluated at that end (the same nine centres that compensate the
    /// point four back). `None` when the newest point was compensated as it came (the path's first points) or
    /// none came yet.
    ///
    /// Why it is within a micron of the final one: the end slope of the quartic is noisier (1.94 sigma / h against
    /// 0.34 sigma / h at the middle), but a slope error `e` moves the contact along the surface by `rho e` and off
    /// it only by `rho e^2 / 2`: 0.06 um for a 2 mm ball at 0.5 mm spacing and 2 um noise. It differs where the
    /// surface bends within the look-ahead more than the quartic can extrapolate (a sharp edge, a dent).
    pub fn preview(&self) -> Option<Compensated> {
        let newest = self.received.checked_sub(1)?;
        if newest < LOOK_AHEAD {
            return None;
        }
        if self.recent.len() < WINDOW {
            let sample = self.recent.last()?;
            return Some(self.reported(newest, sample, Method::Reported(Fallback::PathEnd)));
        }
        let at = self.recent.len() - 1;
        let from = at.saturating_sub(BEHIND);
        self.compensated(newest, &self.recent[from..], at - from, 0, false)
    }

    /// Ends the path: returns the points still to come out, in scan order: those waiting for a roll from what
    /// came, the last `LOOK_AHEAD` along their reported normals (the path's end). The next point pushed starts a
    /// new path.
    pub fn finish(&mut self) -> Vec<Compensated> {
        let mut rest = Vec::new();
        while self.next + LOOK_AHEAD < self.received {
            rest.extend(self.settled(self.next, false));
            self.next += 1;
        }
        let oldest = self.received - self.recent.len();
        rest.extend((self.next..self.received).map(|index| {
            let sample = self.recent[index - oldest];
            self.reported(index, &sample, Method::Reported(Fallback::PathEnd))
        }));
        self.recent.clear();
        self.received = 0;
        self.next = 0;
        self.waiting_roll = None;
        rest
    }

    fn sample(&self, centre: Point3<f64>, reported_normal: Vector3<f64>) -> Sample {
        let normal = reported_normal / reported_normal.norm();
        let tilt = normal.dot(&self.plane_normal);
        let cos_tilt = (1.0 - tilt * tilt).sqrt();
        let rho = if cos_tilt >= MIN_IN_PLANE {
            self.settings.ball_radius_mm / cos_tilt
        } else {
            f64::NAN
        };
        Sample {
            centre,
            normal,
            rho,
        }
    }

    /// The ball moved back along the reported normal and slid into the plane: `c - rho N_plane`.
    fn reported(&self, index: usize, sample: &Sample, method: Method) -> Compensated {
        let w = self.plane_normal.into_inner();
        let in_plane = sample.normal - w * sample.normal.dot(&w);
        let length = in_plane.norm();
        let surface = if sample.rho.is_finite() {
            sample.centre - in_plane / length * sample.rho
        } else {
            // Nothing to slide along: the contact itself, as the machine reports it.
            sample.centre - sample.normal * self.settings.ball_radius_mm
        };
        let method = match method {
            Method::Reported(_) if !sample.rho.is_finite() => {
                Method::Reported(Fallback::NormalOutOfPlane)
            }
            other => other,
        };
        Compensated {
            index,
            surface,
            normal: sample.normal,
            method,
        }
    }

    /// The point at `at` of `history` (the samples that the point's compensation sees, at least a window of
    /// them, the newest last; the point has `LOOK_AHEAD` or more after it, or none for a preview): from the circle
    /// of a roll round an edge through it, if there is one, else from the quartic fit of the window about it (the
    /// window that ends at it, for a preview) in a frame about the point.
    ///
    /// The roll is looked for with the look-ahead, then with each point after it in turn until the centres say
    /// whether it is one (already known too short a roll up to `known_short` points ahead). Where they cannot
    /// tell yet, the point waits (`None`) if `may_wait` and it has waited less than [`ROLL_REACH_AHEAD`] points:
    /// streaming or at once, a point comes out the same.
    fn compensated(
        &self,
        index: usize,
        history: &[Sample],
        at: usize,
        known_short: usize,
        may_wait: bool,
    ) -> Option<Compensated> {
        let ahead = history.len() - 1 - at;
        let first = match known_short {
            0 => LOOK_AHEAD.min(ahead),
            _ => known_short + 1,
        };
        for look_ahead in first..=ahead {
            match self.rolled(index, &history[..=at + look_ahead], at) {
                Ok(rolled) => return Some(rolled),
                Err(RollThrough::TooShortYet) if look_ahead == ahead => {
                    if may_wait && ahead < ROLL_REACH_AHEAD {
                        return None;
                    }
                }
                Err(RollThrough::TooShortYet) => continue,
                Err(_) => break,
            }
        }
        Some(self.fitted(index, &history[..=at + LOOK_AHEAD.min(ahead)], at))
    }

    /// The point at `at` of `history` (the point is the last window's middle, or its end for a preview) from the
    /// quartic fit of the last window's centre path in a frame about the point.
    fn fitted(&self, index: usize, history: &[Sample], at: usize) -> Compensated {
        let window: [Sample; WINDOW] = std::array::from_fn(|i| history[history.len() - WINDOW + i]);
        let at = at + WINDOW - history.len();
        let middle = &window[at];
        let unresolved = Method::Reported(Fallback::Unresolved);
        if window.iter().any(|s| !s.rho.is_finite()) {
            return self.reported(index, middle, unresolved);
        }
        let w = self.plane_normal.into_inner();
        let in_plane = |v: Vector3<f64>| v - w * v.dot(&w);
        // The central-difference chord, or the last step's at the window's end.
        let chord = in_plane(window[(at + 1).min(WINDOW - 1)].centre - window[at - 1].centre);
        if chord.norm() == 0.0 {
            return self.reported(index, middle, unresolved);
        }
        let x_axis = chord.normalize();
        let y_axis = w.cross(&x_axis);
        let (mut xs, mut ys, mut rhos) = ([0.0; WINDOW], [0.0; WINDOW], [0.0; WINDOW]);
        for (j, s) in window.iter().enumerate() {
            let d = s.centre - middle.centre;
            xs[j] = d.dot(&x_axis);
            ys[j] = d.dot(&y_axis);
            rhos[j] = s.rho;
        }
        if xs.windows(2).any(|p| p[1] <= p[0]) {
            return self.reported(index, middle, unresolved);
        }
        let Some(fit) = QuarticFit::new(&xs, &ys, &rhos) else {
            return self.reported(index, middle, unresolved);
        };
        // y' and y'' at the point; rho' per unit x.
        let (slope, bend, rho_dx) = (fit.y_slope, fit.y_bend, fit.rho_slope);
        let stretch = (1.0 + slope * slope).sqrt();
        let tangent = (x_axis + y_axis * slope) / stretch;
        let left = (y_axis - x_axis * slope) / stretch;
        // The material lies opposite the reported normal: it orients the path's normal, nothing more.
        let side = if left.dot(&middle.normal) >= 0.0 {
            1.0
        } else {
            -1.0
        };
        let outward = left * side;
        let path_curvature = side * bend / stretch.powi(3);
        let rho = middle.rho;
        let one_plus = 1.0 + rho * path_curvature;
        let residual_limit =
            (RESIDUAL_SIGMAS * self.settings.noise_sigma_mm).max(RESIDUAL_FLOOR_MM);
        if fit.residual_mm > residual_limit {
            // Flagged only if the window also turns concavely as a whole, from its first centre over its middle
            // to its last: a convex roll's end meeting a face (the path's curvature jumping from 1/rho to 0) defeats
            // the quartic too, and its fit may bend either way at the point; the face's contacts next to a trailing
            // edge's roll were flagged so and left out of the statistics.
            let (first, middle_of_window, last) = (0, WINDOW / 2, WINDOW - 1);
            let (ax, ay) = (
                xs[middle_of_window] - xs[first],
                ys[middle_of_window] - ys[first],
            );
            let (bx, by) = (
                xs[last] - xs[middle_of_window],
                ys[last] - ys[middle_of_window],
            );
            let turns_concavely = side * (ax * by - ay * bx) > 0.0;
            let method = if path_curvature > 0.0 && turns_concavely {
                Method::Flagged(Cusp::UnresolvedConcave {
                    residual_mm: fit.residual_mm,
                })
            } else {
                unresolved
            };
            return self.reported(index, middle, method);
        }
        if one_plus >= 1.0 / self.settings.concave_margin {
            let cusp = Cusp::ConcaveBeyondBall {
                one_minus_rho_kappa: 1.0 / one_plus,
            };
            return self.reported(index, middle, Method::Flagged(cusp));
        }
        if one_plus < -self.settings.convex_tolerance {
            let cusp = Cusp::TighterThanBall {
                one_plus_rho_kappa: one_plus,
            };
            return self.reported(index, middle, Method::Flagged(cusp));
        }
        // d rho / ds along the centre path (seed 002 eq. 1 for circles of varying radius).
        let rho_ds = rho_dx / stretch;
        if rho_ds.abs() >= 1.0 {
            return self.reported(index, middle, unresolved);
        }
        let towards_surface = tangent * rho_ds + outward * (1.0 - rho_ds * rho_ds).sqrt();
        let surface = middle.centre - towards_surface * rho;
        let tilt = middle.normal.dot(&w);
        let normal = towards_surface * (1.0 - tilt * tilt).sqrt() + w * tilt;
        Compensated {
            index,
            surface,
            normal,
            method: Method::PathFit {
                surface_curvature: path_curvature / one_plus,
            },
        }
    }

    /// The point at `at` of `history` compensated from a roll round an edge through it, if its centres make one
    /// (see `roll`): the centre moved back `rho` towards the roll's middle. Else what the centres say of a roll.
    fn rolled(
        &self,
        index: usize,
        history: &[Sample],
        at: usize,
    ) -> Result<Compensated, RollThrough> {
        let w = self.plane_normal.into_inner();
        let u = w
            .cross(&Vector3::x())
            .try_normalize(1e-3)
            .unwrap_or_else(|| w.cross(&Vector3::y()).normalize());
        let v = w.cross(&u);
        let middle = &history[at];
        let in_plane = |p: Vector3<f64>| Vector2::new(p.dot(&u), p.dot(&v));
        let samples: Vec<RollSample> = history
            .iter()
            .map(|s| RollSample {
                centre: in_plane(s.centre - middle.centre),
                rho: s.rho,
                normal: in_plane(s.normal),
            })
            .collect();
        let (outward, edge_radius_mm) =
            match roll_through(&samples, at, self.settings.noise_sigma_mm) {
                RollThrough::Roll {
                    outward,
                    edge_radius_mm,
                } => (outward, edge_radius_mm),
                other => return Err(other),
            };
        let towards_surface = u * outward.x + v * outward.y;
        let tilt = middle.normal.dot(&w);
        Ok(Compensated {
            index,
            surface: middle.centre - towards_surface * middle.rho,
            normal: towards_surface * (1.0 - tilt * tilt).sqrt() + w * tilt,
            method: Method::Roll { edge_radius_mm },
        })
    }
}

/// Compensates a whole scan at once: the points in scan order, each with its reported normal. A `closed` path
/// (the scan returns to its start; the step from its last point to its first a regular step, not a repeat) wraps
/// its windows round, so that every point gets a fit; an open path's ends use the reported normals, as
/// [`Compensator`] does.
pub fn compensate_path(
    settings: CompensationSettings,
    plane_normal: Vector3<f64>,
    points: &[(Point3<f64>, Vector3<f64>)],
    closed: bool,
) -> Vec<Compensated> {
    let mut compensator = Compensator::new(settings, plane_normal);
    if !closed || points.len() < WINDOW {
        let mut out: Vec<Compensated> = points
            .iter()
            .flat_map(|(c, n)| compensator.push(*c, *n))
            .collect();
        out.extend(compensator.finish());
        return out;
    }
    let samples: Vec<Sample> = points
        .iter()
        .map(|(c, n)| compensator.sample(*c, *n))
        .collect();
    let count = samples.len();
    // Each point's history wraps round the closed path, as far back and ahead as the streaming one reaches but
    // never onto itself.
    let back = BEHIND.min(count - 1 - LOOK_AHEAD);
    let ahead = ROLL_REACH_AHEAD.min(count - 1 - back);
    (0..count)
        .map(|i| {
            let history: Vec<Sample> = (0..=back + ahead)
                .map(|j| samples[(i + count * 2 + j - back) % count])
                .collect();
            let compensated = compensator.compensated(i, &history, back, 0, false);
            compensated.expect("a point that may not wait is compensated")
        })
        .collect()
}

/// The least-squares quartics of the centre path's `y` and of `rho` over a window, in `x` scaled to [-1, 1]
/// (solved by QR, as the geometry kernel solves its fits).
struct QuarticFit {
    y_slope: f64,
    y_bend: f64,
    rho_slope: f64,
    /// The fit's residual scale, sqrt(sum of squares / degrees of freedom), mm.
    residual_mm: f64,
}

impl QuarticFit {
    fn new(xs: &[f64; WINDOW], ys: &[f64; WINDOW], rhos: &[f64; WINDOW]) -> Option<Self> {
        let half_width = xs[0].abs().max(xs[WINDOW - 1].abs());
        let design =
            SMatrix::<f64, WINDOW, TERMS>::from_fn(|i, k| (xs[i] / half_width).powi(k as i32));
        let mut values = SMatrix::<f64, WINDOW, 2>::zeros();
        for i in 0..WINDOW {
            values[(i, 0)] = ys[i];
            values[(i, 1)] = rhos[i];
        }
        let qr = design.qr();
        let projected = qr.q().transpose() * values;
        let coefficients = qr.r().solve_upper_triangular(&projected)?;
        let residuals: SVector<f64, WINDOW> = (design * coefficients - values).column(0).into();
        let residual_mm = (residuals.norm_squared() / (WINDOW - TERMS) as f64).sqrt();
        Some(QuarticFit {
            y_slope: coefficients[(1, 0)] / half_width,
            y_bend: 2.0 * coefficients[(2, 0)] / (half_width * half_width),
            rho_slope: coefficients[(1, 1)] / half_width,
            residual_mm,
        })
    }
}

#[cfg(test)]
mod tests;
