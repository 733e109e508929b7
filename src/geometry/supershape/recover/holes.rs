//! Holes (seed 001 section 6.2): "points belonging to the borders of the cavity introduce an important
//! reconstruction error because they are located inside the reconstructed supershape". Points well inside the
//! envelope are set apart, the envelope is fitted again without them (they had pulled it inwards), and so on until
//! the split settles; the points set apart are clustered into cavities, each fitted as a supershape of its own and
//! subtracted from the envelope.
//!
//! A bore's scan has only its wall: nothing fixes where a supershape fitted to it closes. A cavity whose points
//! run through the envelope along the fitted hole's axis is a through hole, and its supershape is made a prism of
//! the same middle section (square r2 of very high exponents, as `prism` does) longer than the part, so that it
//! opens the envelope at both ends instead of leaving a skin over them.

use nalgebra::{Point3, Vector3};

use super::{fit_one, Envelope, Fitted, RecoveryError};
use crate::geometry::supershape::deform::Deformations;
use crate::geometry::supershape::prism::SQUARE;
use crate::geometry::supershape::shape::Supershape;

/// A point is in a cavity when F2 (its relative depth inside the envelope) is above this many robust standard
/// deviations of F2 over all points, and above `MIN_DEPTH`.
const DEPTH_SIGMAS: f64 = 8.0;
const MIN_DEPTH: f64 = 0.04;
/// A cavity needs this many points (and 1% of the scan) to be fitted.
const MIN_HOLE_POINTS: usize = 40;
/// Rounds of refitting the envelope without the cavities' points.
const ROUNDS: usize = 3;
/// Points of one cavity are within this many median nearest-neighbour spacings of another of its points.
const LINK_SPACINGS: f64 = 4.0;
/// A cavity whose points span this fraction of the envelope's extent along its axis runs through it.
const THROUGH_FRACTION: f64 = 0.8;

/// A cavity's supershape (normalised frame) with what was found about it.
pub(super) struct HoleFit {
    pub fitted: Fitted,
    pub points: usize,
    pub through: bool,
    /// The envelope's extent along the hole's axis (normalised units): a through hole's prism is this long on
    /// either side of its centre.
    pub length: f64,
}

/// The envelope fitted without the cavities' points, the indices of its own points, and the cavities' fits. The
/// first envelope is fitted to the points' outer shell (`outer_shell`): a fit to every point would be pulled
/// inwards by the cavities' walls, or worse, too far for their points to stand out as inside. Without cavities the
/// envelope is fitted to every point.
pub(super) fn separate(
    points: &[Point3<f64>],
    model: Envelope,
) -> Result<(Fitted, Vec<usize>, Vec<HoleFit>), RecoveryError> {
    let least = MIN_HOLE_POINTS.max(points.len() / 100);
    let all: Vec<usize> = (0..points.len()).collect();
    let shell: Vec<Point3<f64>> = outer_shell(points).iter().map(|&i| points[i]).collect();
    let mut envelope = model.fit(&shell)?;
    let mut inner = interior(&envelope, points);
    if inner.len() < least {
        return Ok((model.fit(points)?, all, Vec::new()));
    }
    for _ in 0..ROUNDS {
        let outer: Vec<Point3<f64>> = complement(&inner, points.len())
            .iter()
            .map(|&i| points[i])
            .collect();
        if let Some(candidate) = model.refine(&outer, &envelope.candidate) {
            envelope.candidate = candidate;
        }
        let next = interior(&envelope, points);
        if next == inner {
            break;
        }
        inner = next;
    }
    if inner.len() < least {
        return Ok((model.fit(points)?, all, Vec::new()));
    }
    let outer = complement(&inner, points.len());
    let outer_points: Vec<Point3<f64>> = outer.iter().map(|&i| points[i]).collect();
    let mut holes = Vec::new();
    for cluster in clusters(&inner, points) {
        if cluster.len() < least {
            continue;
        }
        let cavity: Vec<Point3<f64>> = cluster.iter().map(|&i| points[i]).collect();
        // The envelope's family and symmetry are its own; a cavity's are read from its points. A cavity that fits no
        // supershape is left out (its points stay set apart from the envelope's) rather than failing the part.
        let Ok(fitted) = fit_one(&cavity, None) else {
            continue;
        };
        let axis = fitted.candidate.rotation() * Vector3::z();
        let span = |set: &[Point3<f64>]| {
            let along = set.iter().map(|p| p.coords.dot(&axis));
            let (low, high) = along.fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), t| {
                (l.min(t), h.max(t))
            });
            high - low
        };
        let length = span(&outer_points);
        holes.push(HoleFit {
            through: span(&cavity) >= THROUGH_FRACTION * length,
            points: cavity.len(),
            fitted,
            length,
        });
    }
    Ok((envelope, outer, holes))
}

/// A through hole's supershape as a prism of its middle section, `length` (mm) either side of its centre.
pub(super) fn through_prism(
    shape: Supershape,
    place: Deformations,
    length: f64,
) -> (Supershape, Deformations) {
    let mut prism = shape;
    prism.r2 = SQUARE;
    prism.scale[2] = length;
    (prism, place)
}

/// The points farthest from the centroid in their direction: in each of 24 x 12 bins of direction (longitude, and
/// latitude evenly in its sine) the points within 15% of the bin's largest radius. A cavity's wall lies nearer the
/// centre than the envelope in the same directions.
fn outer_shell(points: &[Point3<f64>]) -> Vec<usize> {
    const BINS: (usize, usize) = (24, 12);
    let centroid = points.iter().map(|p| p.coords).sum::<Vector3<f64>>() / points.len() as f64;
    let bin_of = |p: &Point3<f64>| {
        let d = p.coords - centroid;
        let r = d.norm();
        let longitude = ((d.y.atan2(d.x) + std::f64::consts::PI) / std::f64::consts::TAU
            * BINS.0 as f64) as usize;
        let latitude = (((d.z / r.max(f64::MIN_POSITIVE)) + 1.0) / 2.0 * BINS.1 as f64) as usize;
        (
            longitude.min(BINS.0 - 1) * BINS.1 + latitude.min(BINS.1 - 1),
            r,
        )
    };
    let mut largest = vec![0.0f64; BINS.0 * BINS.1];
    for p in points {
        let (bin, r) = bin_of(p);
        largest[bin] = largest[bin].max(r);
    }
    (0..points.len())
        .filter(|&i| {
            let (bin, r) = bin_of(&points[i]);
            r >= 0.85 * largest[bin]
        })
        .collect()
}

/// The indices of the points well inside the envelope.
fn interior(envelope: &Fitted, points: &[Point3<f64>]) -> Vec<usize> {
    let (shape, place) = envelope.candidate.supershape();
    let depths: Vec<f64> = points
        .iter()
        .map(|p| shape.radial(&place.inverse(p)))
        .collect();
    let mut absolute: Vec<f64> = depths.iter().map(|d| d.abs()).collect();
    absolute.sort_by(f64::total_cmp);
    let sigma = 1.4826 * absolute[absolute.len() / 2];
    let threshold = (DEPTH_SIGMAS * sigma).max(MIN_DEPTH);
    (0..points.len())
        .filter(|&i| depths[i] > threshold)
        .collect()
}

fn complement(inner: &[usize], count: usize) -> Vec<usize> {
    let mut is_inner = vec![false; count];
    for &i in inner {
        is_inner[i] = true;
    }
    (0..count).filter(|&i| !is_inner[i]).collect()
}

/// Single-linkage clusters of the indexed points, linked within `LINK_SPACINGS` median nearest-neighbour spacings.
fn clusters(indices: &[usize], points: &[Point3<f64>]) -> Vec<Vec<usize>> {
    let at = |k: usize| points[indices[k]];
    let n = indices.len();
    let mut nearest: Vec<f64> = (0..n)
        .map(|a| {
            (0..n)
                .filter(|&b| b != a)
                .map(|b| (at(a) - at(b)).norm())
                .fold(f64::INFINITY, f64::min)
        })
        .collect();
    nearest.sort_by(f64::total_cmp);
    let link = LINK_SPACINGS * nearest[n / 2];
    let mut parent: Vec<usize> = (0..n).collect();
    fn root(parent: &mut [usize], mut k: usize) -> usize {
        while parent[k] != k {
            parent[k] = parent[parent[k]];
            k = parent[k];
        }
        k
    }
    for a in 0..n {
        for b in a + 1..n {
            if (at(a) - at(b)).norm() <= link {
                let (ra, rb) = (root(&mut parent, a), root(&mut parent, b));
                parent[ra] = rb;
            }
        }
    }
    let mut groups: std::collections::BTreeMap<usize, Vec<usize>> = Default::default();
    for (k, &index) in indices.iter().enumerate() {
        let r = root(&mut parent, k);
        groups.entry(r).or_default().push(index);
    }
    groups.into_values().collect()
}
