//! Exact distances to a profile stack. The stack is piecewise: each segment is a smooth 3-D polynomial between
//! two profile planes, and the surface has a crease at every inner profile. Newton cannot converge on a crease,
//! so the nearest point is found as the best of (a) each nearby segment's own foot, kept only when it lies within
//! the segment's slab, and (b) the nearest point of each profile curve, in its plane (a crease foot).
//!
//! The best is then proved the global minimum, segment by segment over every slab the disk about the point
//! reaches: the certificate's box search ([`super::certificate`]) over the disk clipped to the closed slab, less
//! the ball its proof clears about the foot when the foot is the segment's own, and the balls the crease proof
//! clears about each bounding profile's nearest point. The boxes cover the slab's faces, so the profiles' curves
//! are proved with it. A zero the boxes show nearer is a critical point of the segment's polynomial within its
//! slab: it refutes the foot, and the proof starts again from it.

use std::ops::RangeInclusive;
use std::sync::atomic::{AtomicUsize, Ordering};

use nalgebra::{Vector2, Vector3};

use super::certificate::{Certifier, Slab, Verdict};
use super::{lagrange_newton, DistanceError, ExactDistance, Foot};
use crate::geometry::implicit::{Implicit, IpModel};
use crate::geometry::interp::ProfileStack;
use crate::geometry::sampling::{Aabb, ZeroSetSamples};

/// Sampling of each segment's zero set: cells along x per segment, and across (y, z).
const SEGMENT_CELLS_ALONG: usize = 4;
const SEGMENT_CELLS_ACROSS: usize = 256;
const PROFILE_CELLS: usize = 512;
/// Points this far beyond the first or last profile plane still count as on it (a probe's x scatters too).
const PLANE_TOLERANCE_MM: f64 = 0.05;
/// Each profile's samples nearest to a point seed its segments' Newton runs: up to this many, spread apart, from
/// this many nearest, no farther than the nearest by this much (the distances measured are within 5 mm).
const LIFTED_SEEDS: usize = 8;
const LIFTED_SCANNED: usize = 256;
const LIFTED_REACH_MM: f64 = 10.0;
/// Seeds closer to one taken than this fraction of their distance from the point are passed over.
const SEED_SPREAD: f64 = 0.2;
/// How many times a foot refuted by a segment's certificate is replaced by the nearer one and proved again.
const REFUTATIONS_FOLLOWED: usize = 16;

pub struct StackDistance<'a> {
    stack: &'a ProfileStack,
    segments: Vec<(IpModel<3>, ZeroSetSamples<3>)>,
    profiles: Vec<ZeroSetSamples<2>>,
    uncertified: AtomicUsize,
}

/// Where a foot lies: within a segment (a critical point of its polynomial) or on a profile's curve.
#[derive(Debug, Clone, Copy, PartialEq)]
enum On {
    Segment(usize),
    Crease(usize),
}

impl<'a> StackDistance<'a> {
    /// `profile_domains`: the data box of each profile, in stack order.
    pub fn new(stack: &'a ProfileStack, profile_domains: &[Aabb<2>]) -> Self {
        let bounds = stack.bounds(profile_domains);
        let xs: Vec<f64> = stack.profiles().iter().map(|p| p.x).collect();
        let segments = (0..xs.len() - 1)
            .map(|k| {
                let model = stack.segment_model(k);
                let slab = Aabb {
                    min: Vector3::new(xs[k], bounds.min.y, bounds.min.z),
                    max: Vector3::new(xs[k + 1], bounds.max.y, bounds.max.z),
                };
                let counts = [
                    SEGMENT_CELLS_ALONG,
                    SEGMENT_CELLS_ACROSS,
                    SEGMENT_CELLS_ACROSS,
                ];
                let samples = ZeroSetSamples::with_counts(&model, &slab, counts);
                (model, samples)
            })
            .collect();
        let profiles = stack
            .profiles()
            .iter()
            .zip(profile_domains)
            .map(|(p, domain)| ZeroSetSamples::new(&p.model, &domain.scaled(2.0), PROFILE_CELLS))
            .collect();
        Self {
            stack,
            segments,
            profiles,
            uncertified: AtomicUsize::new(0),
        }
    }

    /// How many feet found so far could not be proved the global minimum.
    pub fn uncertified(&self) -> usize {
        self.uncertified.load(Ordering::Relaxed)
    }

    pub fn foot(&self, p: &Vector3<f64>) -> Result<Foot<3>, DistanceError> {
        let profiles = self.stack.profiles();
        // Beyond the end profiles the blend is an extrapolation, not a model of the part.
        let (first, last) = (profiles[0].x, profiles[profiles.len() - 1].x);
        if p.x < first - PLANE_TOLERANCE_MM || p.x > last + PLANE_TOLERANCE_MM {
            return Err(DistanceError::OutsideModelRange);
        }
        let mut search = Search {
            stack: self,
            p,
            outside: self.stack.value(p) >= 0.0,
            creases: vec![None; profiles.len()],
            proved: true,
            best: None,
        };
        let k = self.stack.segment_at(p.x);
        let around = k.saturating_sub(1)..=(k + 1).min(self.segments.len() - 1);
        for j in around.clone() {
            if let Some(foot) = self.segment_foot(j, p) {
                search.consider(search.signed(foot.point), On::Segment(j));
            }
        }
        // The profiles are creases of the surface: those within the best foot's distance are looked at as the
        // proof goes; only where no segment has a foot within its slab do the point's own segment's profiles
        // give the first one.
        if search.best.is_none() {
            search.crease(k);
            search.crease(k + 1);
        }
        let found = search.prove();
        if !search.proved {
            self.uncertified.fetch_add(1, Ordering::Relaxed);
        }
        found
    }

    /// Segment j's own foot of p, the nearest of those Newton finds within the segment's slab from its seeds: the
    /// seeded search over its sampled zero set, and its two profiles' samples nearest to p lifted to p's x. The
    /// segment's samples lie in a few planes along x (each segment is long); the profiles' are dense, and a blade
    /// changes slowly along its stack, so a lifted sample lies close to the segment's zero set beside p.
    fn segment_foot(&self, j: usize, p: &Vector3<f64>) -> Option<Foot<3>> {
        let (model, samples) = &self.segments[j];
        let slab = self.slab(j);
        let within = |foot: &Foot<3>| foot.point.x >= slab.lo && foot.point.x <= slab.hi;
        // The segment's polynomial stands for the part only between its planes: its search is not certified over
        // its whole zero set; the stack's own proof, clipped to the slab, follows.
        let searched = ExactDistance::new(model, samples)
            .uncertified_foot(p, None)
            .ok()
            .filter(within);
        let x = p.x.clamp(slab.lo, slab.hi);
        let lifted = [j, j + 1]
            .into_iter()
            .flat_map(|plane| self.spread_seeds(plane, &Vector2::new(p.y, p.z)));
        lifted
            .filter_map(|seed| lagrange_newton(model, p, &Vector3::new(x, seed.x, seed.y)))
            .filter(within)
            .chain(searched)
            .min_by(|a, b| a.distance.abs().total_cmp(&b.distance.abs()))
    }

    /// Profile `plane`'s samples nearest to q, each a fair fraction of its distance from those taken before it:
    /// round a nose or a thin edge the nearest samples crowd on one side, while the nearest point may lie on
    /// another.
    fn spread_seeds(&self, plane: usize, q: &Vector2<f64>) -> Vec<Vector2<f64>> {
        let mut seeds: Vec<Vector2<f64>> = Vec::with_capacity(LIFTED_SEEDS);
        let mut nearest = None;
        for seed in self.profiles[plane].nearest_iter(q).take(LIFTED_SCANNED) {
            let away = (q - seed).norm();
            let first = *nearest.get_or_insert(away);
            if seeds.len() == LIFTED_SEEDS || away > first + LIFTED_REACH_MM {
                break;
            }
            if seeds
                .iter()
                .all(|s| (s - seed).norm() >= SEED_SPREAD * away)
            {
                seeds.push(seed);
            }
        }
        seeds
    }

    fn slab(&self, j: usize) -> Slab {
        let profiles = self.stack.profiles();
        Slab {
            lo: profiles[j].x,
            hi: profiles[j + 1].x,
        }
    }

    /// The segments whose slabs come within `d` of x.
    fn segments_within(&self, x: f64, d: f64) -> RangeInclusive<usize> {
        let profiles = self.stack.profiles();
        let last = self.segments.len() - 1;
        let lo = (0..=last)
            .find(|&j| profiles[j + 1].x >= x - d)
            .unwrap_or(last);
        let hi = (lo..=last)
            .rev()
            .find(|&j| profiles[j].x <= x + d)
            .unwrap_or(lo);
        lo..=hi
    }
}

/// One point's search: the best foot so far, and each profile's nearest point once found.
struct Search<'s, 'a> {
    stack: &'s StackDistance<'a>,
    p: &'s Vector3<f64>,
    /// The side of p, which signs every foot (a crease foot has no one normal to sign it by).
    outside: bool,
    /// Each profile's nearest point to p in its plane, once looked for (`Some(None)`: it has none).
    creases: Vec<Option<Option<Foot<3>>>>,
    /// False once a proof could not be finished.
    proved: bool,
    best: Option<(Foot<3>, On)>,
}

impl Search<'_, '_> {
    fn signed(&self, point: Vector3<f64>) -> Foot<3> {
        let unsigned = (self.p - point).norm();
        Foot {
            point,
            distance: if self.outside { unsigned } else { -unsigned },
        }
    }

    /// Keeps `foot` if it is the nearest yet.
    fn consider(&mut self, foot: Foot<3>, on: On) {
        if self
            .best
            .is_none_or(|(b, _)| foot.distance.abs() < b.distance.abs())
        {
            self.best = Some((foot, on));
        }
    }

    /// Profile `plane`'s nearest point to p, in its plane, looked for once and considered. Whether it is the
    /// profile's nearest is for the segments' proofs to say (their slabs' faces hold the profile).
    fn crease(&mut self, plane: usize) -> Option<Foot<3>> {
        if let Some(known) = self.creases[plane] {
            return known;
        }
        let profile = &self.stack.stack.profiles()[plane];
        let exact = ExactDistance::new(&profile.model, &self.stack.profiles[plane]);
        let found = exact
            .foot(&Vector2::new(self.p.y, self.p.z), None)
            .ok()
            .map(|in_plane| {
                self.signed(Vector3::new(profile.x, in_plane.point.x, in_plane.point.y))
            });
        self.creases[plane] = Some(found);
        if let Some(foot) = found {
            self.consider(foot, On::Crease(plane));
            // A segment's own foot near its face is found best from the crease: the samples lie a few
            // millimetres apart along x, and Newton from them can settle on a farther critical point.
            let segments = plane.saturating_sub(1)..=plane.min(self.stack.segments.len() - 1);
            for j in segments {
                let (model, _) = &self.stack.segments[j];
                if let Some(inner) = lagrange_newton(model, self.p, &foot.point) {
                    let slab = self.stack.slab(j);
                    if slab.lo <= inner.point.x && inner.point.x <= slab.hi {
                        self.consider(self.signed(inner.point), On::Segment(j));
                    }
                }
            }
        }
        found
    }

    /// Proves the best foot over every slab within its distance, following any nearer zero a proof shows.
    fn prove(&mut self) -> Result<Foot<3>, DistanceError> {
        'rounds: for _ in 0..=REFUTATIONS_FOLLOWED {
            let Some((best, on)) = self.best else {
                return Err(DistanceError::NoFootPoint);
            };
            let d = best.distance.abs();
            let segments = self.stack.segments_within(self.p.x, d);
            let profiles = self.stack.stack.profiles();
            let planes = *segments.start()..=*segments.end() + 1;
            for (plane, profile) in profiles
                .iter()
                .enumerate()
                .take(planes.end() + 1)
                .skip(*planes.start())
            {
                if (profile.x - self.p.x).abs() < d {
                    self.crease(plane);
                }
            }
            if self
                .best
                .is_some_and(|(nearest, _)| nearest.distance.abs() < d)
            {
                continue 'rounds;
            }
            for j in segments {
                let (model, _) = &self.stack.segments[j];
                let mut certifier = Certifier::within(model, self.stack.slab(j));
                // A crease's ball clears the segment's side of it (plane j bounds the slab below, j + 1 above).
                let clear = [(j, 1.0), (j + 1, -1.0)]
                    .into_iter()
                    .filter_map(|(plane, side)| {
                        // A profile beyond the disk's reach bounds nothing the disk holds.
                        if (profiles[plane].x - self.p.x).abs() >= d {
                            return None;
                        }
                        let crease = self.creases[plane].flatten()?;
                        certifier.crease_ball(self.p, &crease.point, crease.distance.abs(), side)
                    })
                    .collect::<Vec<_>>();
                let verdict = if on == On::Segment(j) {
                    let (value, gradient) = model.value_gradient(&best.point);
                    certifier.check_at(self.p, &best.point, d, value, &gradient, clear)
                } else {
                    certifier.check_clear(self.p, d, clear)
                };
                match verdict {
                    Verdict::Certified => {}
                    Verdict::Nearer(nearer) => {
                        self.consider(self.signed(nearer.point), On::Segment(j));
                        continue 'rounds;
                    }
                    Verdict::Unknown => self.proved = false,
                }
            }
            return Ok(best);
        }
        self.proved = false;
        self.best
            .map(|(foot, _)| foot)
            .ok_or(DistanceError::NoFootPoint)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::implicit::Frame;
    use crate::geometry::interp::Profile;
    use crate::geometry::poly::Poly;

    fn circle(radius: f64) -> IpModel<2> {
        IpModel {
            frame: Frame::identity(),
            poly: Poly::new(
                2,
                vec![-radius / 2.0, 0.0, 0.0, 0.5 / radius, 0.0, 0.5 / radius],
            ),
        }
    }

    /// The stack fitted (degree 8, `zeroset fit ip --stack`) to the simulated blade's five NACA profiles: thin
    /// sections whose far faces and trailing edges are within reach of points a few millimetres away.
    fn blade_stack() -> (ProfileStack, Vec<Aabb<2>>) {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("config/models/naca-blade-a-stack-degree-8.json");
        let file = crate::model_file::ModelFile::load(&path).unwrap();
        let crate::model_file::ReferenceModel::Stack { mut profiles } = file.model else {
            panic!("{} holds no stack", path.display());
        };
        profiles.sort_by(|a, b| a.x.total_cmp(&b.x));
        let domains = profiles.iter().map(|p| p.fitted.domain).collect();
        (crate::model_file::stack_of(&profiles).unwrap(), domains)
    }

    /// Points of every segment's zero set within its slab, sampled densely (about 0.7 mm apart across, 2 mm along
    /// x), each tagged with its segment: every one is a point of the stack's surface.
    fn dense_surface(stack: &ProfileStack, domains: &[Aabb<2>]) -> Vec<(Vector3<f64>, usize)> {
        let bounds = stack.bounds(domains);
        let xs: Vec<f64> = stack.profiles().iter().map(|p| p.x).collect();
        (0..xs.len() - 1)
            .flat_map(|k| {
                let model = stack.segment_model(k);
                let slab = Aabb {
                    min: Vector3::new(xs[k], bounds.min.y, bounds.min.z),
                    max: Vector3::new(xs[k + 1], bounds.max.y, bounds.max.z),
                };
                let along = ((xs[k + 1] - xs[k]) / 2.0).ceil() as usize;
                let samples = ZeroSetSamples::with_counts(&model, &slab, [along, 200, 200]);
                samples
                    .points()
                    .iter()
                    .filter(|q| q.x >= xs[k] && q.x <= xs[k + 1])
                    .map(|q| (*q, k))
                    .collect::<Vec<_>>()
            })
            .collect()
    }

    #[test]
    fn distances_to_a_fitted_blade_stack_are_certified_global_minima() {
        let campaign = check_against_the_sampled_surface(500, 2412);
        assert_eq!(campaign.unproved, 0, "{campaign:?}");
        assert_eq!(campaign.farther, 0, "{campaign:?}");
    }

    /// The campaign: `cargo test --release --lib blade_stack_campaign -- --ignored --nocapture`. No foot
    /// may lie farther than the reference; those the certificate could not prove are counted and printed.
    #[test]
    #[ignore = "100 000 points: minutes in a release build"]
    fn blade_stack_campaign() {
        let campaign = check_against_the_sampled_surface(100_000, 7);
        println!("{campaign:?}");
        assert_eq!(campaign.farther, 0, "{campaign:?}");
    }

    /// Points where the stack's distance before its certificate took a local foot (found by this check over
    /// 30 000 points, seed 2412): 0.1-1.3 mm too far, near the blade's leading edge and inside the section.
    const ONCE_LOCAL: [[f64; 3]; 6] = [
        [200.710583, 56.273681, 28.711699],
        [195.177994, 59.675462, 38.718937],
        [105.644125, 82.587812, 50.062777],
        [471.429911, -35.242767, -11.787687],
        [399.706357, 73.600185, 33.324518],
        [101.970601, 77.573251, 48.731551],
    ];

    /// Points the campaign (seed 7) left unproved before the boxes left over when the budget runs out started
    /// Newton, and before a small box that Newton did not settle was split on: the first lies near a centre of
    /// curvature and took a local foot 76 um too far; the second's foot, on the profile at x = 400 mm, was right.
    /// The third's foot was refuted again and again by itself, found anew with its rounding, until the rounds ran
    /// out.
    const ONCE_UNPROVED: [[f64; 3]; 3] = [
        [101.59425401821211, 76.80037560486106, 48.3262859350777],
        [400.616201542648, 61.143388003646606, 24.492713775724987],
        [395.3932582193534, 63.809151336396866, 19.74906114491656],
    ];

    /// What a check found: feet farther than the reference (by more than 1e-6 mm), how many of them proved, and
    /// by how much at most (mm); feet left unproved.
    #[derive(Debug, Default)]
    struct Campaign {
        points: usize,
        inside: usize,
        unproved: usize,
        farther: usize,
        proved_farther: usize,
        farthest_mm: f64,
    }

    /// An independent check of the stack's distances: before its certificate, 6 of 30 000 points within 5 mm of
    /// this stack took a local foot, up to 1.3 mm too far ([`ONCE_LOCAL`]). Here: those, then `count` seeded
    /// points within 5 mm; each foot must be on the surface and on the point's side, and is counted farther if it
    /// lies more than 1e-6 mm beyond any point sampled on the surface or any of the 24 samples nearest to p
    /// polished by Newton on its own segment.
    fn check_against_the_sampled_surface(count: usize, seed: u64) -> Campaign {
        use rand::{Rng, SeedableRng};
        let (stack, domains) = blade_stack();
        let distance = StackDistance::new(&stack, &domains);
        let surface = dense_surface(&stack, &domains);
        let tree = rstar::RTree::bulk_load(
            surface
                .iter()
                .enumerate()
                .map(|(i, (q, _))| rstar::primitives::GeomWithData::new([q.x, q.y, q.z], i))
                .collect(),
        );
        let models: Vec<IpModel<3>> = (0..4).map(|k| stack.segment_model(k)).collect();
        let (first, last) = (stack.profiles()[0].x, stack.profiles()[4].x);
        let mut campaign = Campaign::default();
        // Checks one point; false if it lies more than 5 mm from the surface.
        let mut check = |p: Vector3<f64>| {
            // The sampled surface's nearest points, polished on their segments within their slabs.
            let mut reference = f64::INFINITY;
            let mut sampled = f64::INFINITY;
            for q in tree.nearest_neighbor_iter([p.x, p.y, p.z]).take(24) {
                let (point, k) = surface[q.data];
                sampled = sampled.min((p - point).norm());
                reference = reference.min(sampled);
                let slab = stack.profiles()[k].x..=stack.profiles()[k + 1].x;
                if let Some(foot) =
                    crate::geometry::distance::lagrange_newton(&models[k], &p, &point)
                {
                    if slab.contains(&foot.point.x) {
                        reference = reference.min(foot.distance.abs());
                    }
                }
            }
            if sampled > 5.0 {
                return false;
            }
            let unproved = distance.uncertified();
            let foot = distance.foot(&p).unwrap();
            let proved = distance.uncertified() == unproved;
            let (value, gradient) = stack.value_gradient(&foot.point);
            assert!(
                value.abs() / gradient.norm() < 1e-6
                    && foot.point.x >= first
                    && foot.point.x <= last,
                "at {p}: the foot {} is off the surface",
                foot.point
            );
            assert_eq!(foot.distance.signum(), stack.value(&p).signum(), "at {p}");
            let beyond = foot.distance.abs() - reference;
            campaign.points += 1;
            campaign.inside += usize::from(foot.distance < -1.0);
            campaign.unproved += usize::from(!proved);
            if !proved {
                println!(
                    "at [{}, {}, {}]: {} mm, unproved ({:+e} mm from the reference)",
                    p.x,
                    p.y,
                    p.z,
                    foot.distance,
                    foot.distance.abs() - reference
                );
            }
            if beyond > 1e-6 {
                println!(
                    "at {p}: {} mm, {beyond} mm beyond the reference (proved: {proved})",
                    foot.distance
                );
                campaign.farther += 1;
                campaign.proved_farther += usize::from(proved);
                campaign.farthest_mm = campaign.farthest_mm.max(beyond);
            }
            true
        };
        for p in ONCE_LOCAL.iter().chain(&ONCE_UNPROVED) {
            assert!(check(Vector3::from(*p)), "{p:?} lies within 5 mm");
        }
        let bounds = stack.bounds(&domains).scaled(0.6);
        let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
        let mut checked = 0;
        while checked < count {
            let p = Vector3::new(
                rng.gen_range(first..last),
                rng.gen_range(bounds.min.y..bounds.max.y),
                rng.gen_range(bounds.min.z..bounds.max.z),
            );
            checked += usize::from(check(p));
        }
        println!(
            "{} points within 5 mm of the stack, against {} surface samples: {campaign:?}",
            campaign.points,
            surface.len()
        );
        assert!(
            campaign.inside > count / 20,
            "{campaign:?}: too few points inside"
        );
        campaign
    }

    #[test]
    fn distances_to_a_stack_of_circles_match_the_cone_and_its_creases() {
        // Circles of radius 10 and 20 mm at x = 0 and 100, radius 10 again at 200: the blend is not exactly a
        // cone (F blends, not radii), so the reference is a dense numerical minimum over the surface.
        let stack = ProfileStack::new(vec![
            Profile {
                x: 0.0,
                model: circle(10.0),
            },
            Profile {
                x: 100.0,
                model: circle(20.0),
            },
            Profile {
                x: 200.0,
                model: circle(10.0),
            },
        ])
        .unwrap();
        let domains = vec![
            Aabb {
                min: Vector2::new(-10.0, -10.0),
                max: Vector2::new(10.0, 10.0),
            },
            Aabb {
                min: Vector2::new(-20.0, -20.0),
                max: Vector2::new(20.0, 20.0),
            },
            Aabb {
                min: Vector2::new(-10.0, -10.0),
                max: Vector2::new(10.0, 10.0),
            },
        ];
        let distance = StackDistance::new(&stack, &domains);
        // The surface's radius at x, from F(x, r) = 0 of the blend along the y axis.
        let radius_at = |x: f64| {
            let (mut lo, mut hi) = (0.0, 40.0);
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if stack.value(&Vector3::new(x, mid, 0.0)) < 0.0 {
                    lo = mid
                } else {
                    hi = mid
                }
            }
            0.5 * (lo + hi)
        };
        let profile: Vec<(f64, f64)> = (0..=4_000)
            .map(|i| {
                let x = i as f64 * 0.05;
                (x, radius_at(x))
            })
            .collect();
        let points: [Vector3<f64>; 5] = [
            Vector3::new(50.0, 25.0, 0.0),
            Vector3::new(100.0, 0.0, 24.0),
            Vector3::new(100.0, 15.0, 0.0),
            Vector3::new(150.0, 3.0, 4.0),
            Vector3::new(99.0, 0.0, 21.0),
        ];
        for p in points {
            let r = (p.y * p.y + p.z * p.z).sqrt();
            let reference = profile
                .iter()
                .map(|(x, radius)| ((p.x - x).powi(2) + (r - radius).powi(2)).sqrt())
                .fold(f64::INFINITY, f64::min);
            let foot = distance.foot(&p).unwrap();
            assert!(
                (foot.distance.abs() - reference).abs() < 2e-3,
                "at {p}: {} vs {reference}",
                foot.distance
            );
            assert_eq!(foot.distance.signum(), stack.value(&p).signum());
        }
        assert_eq!(
            distance.foot(&Vector3::new(200.2, 10.0, 0.0)),
            Err(DistanceError::OutsideModelRange)
        );
        assert_eq!(
            distance.foot(&Vector3::new(-1.0, 10.0, 0.0)),
            Err(DistanceError::OutsideModelRange)
        );
    }
}
