//! Parts of several segments (seed 001 section 6.3): "since segmented data can be seen as the union of several
//! parts, the union of the reconstructed parts can be transcribed into a single analytical equation using
//! R-functions", R_p with p = 2. Each segment is recovered on its own as a truncated supershape (its points show
//! only the part's outside, so the envelope is cut to where they are, unless the options say not to truncate),
//! with its holes, and the recovered solids
//! are joined by union; the global error of fit (eq. 15) is the whole object's, over every segment's points.
//! The segmentation itself is the scan's (a label per point), as in the paper, which takes it from a mesh
//! segmentation.

use nalgebra::Point3;

use super::{global_error, recover, Recovered, RecoveryError, RecoveryOptions, MIN_POINTS};
use crate::geometry::supershape::csg::{Node, Solid};
use crate::geometry::supershape::rfunc::{Boolean, RFunction};

/// The points of one segment of a part, mm.
#[derive(Debug, Clone, PartialEq)]
pub struct SegmentPoints {
    pub label: String,
    pub points: Vec<Point3<f64>>,
}

/// One segment's recovery.
#[derive(Debug, Clone, PartialEq)]
pub struct RecoveredSegment {
    pub label: String,
    pub recovered: Recovered,
}

/// A part recovered from its segments: the union of theirs.
#[derive(Debug, Clone, PartialEq)]
pub struct RecoveredObject {
    pub solid: Solid,
    pub segments: Vec<RecoveredSegment>,
    /// Seed 001 eq. 15 of the union at every segment's points, mm^3.
    pub global_error: f64,
}

/// Why a segmented part was not recovered: the segment at fault and why.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SegmentError {
    #[error("no segments to recover")]
    Empty,
    #[error("segment '{label}': {error}")]
    Segment { label: String, error: RecoveryError },
}

/// Recovers every segment with `options` (truncation as the paper does when `options.truncate`) and joins them
/// by R_p (p = 2) union, segment by segment in their order. `starting` hears of each segment (its index) before
/// its recovery, which takes seconds.
pub fn recover_segments(
    segments: &[SegmentPoints],
    options: &RecoveryOptions,
    starting: &mut dyn FnMut(usize, &SegmentPoints),
) -> Result<RecoveredObject, SegmentError> {
    // A segment too small to fit is told before the others' recoveries take their seconds.
    if let Some(small) = segments.iter().find(|s| s.points.len() < MIN_POINTS) {
        return Err(SegmentError::Segment {
            label: small.label.clone(),
            error: RecoveryError::TooFewPoints {
                got: small.points.len(),
            },
        });
    }
    let recovered: Vec<RecoveredSegment> = segments
        .iter()
        .enumerate()
        .map(|(k, segment)| {
            starting(k, segment);
            recover(&segment.points, options)
                .map(|recovered| RecoveredSegment {
                    label: segment.label.clone(),
                    recovered,
                })
                .map_err(|error| SegmentError::Segment {
                    label: segment.label.clone(),
                    error,
                })
        })
        .collect::<Result<_, _>>()?;
    let root = recovered
        .iter()
        .map(|s| s.recovered.solid.root().clone())
        .reduce(|union, next| Node::boolean(Boolean::Union, RFunction::P(2), union, next))
        .ok_or(SegmentError::Empty)?;
    let solid = Solid::new(root);
    let all: Vec<Point3<f64>> = segments.iter().flat_map(|s| s.points.clone()).collect();
    Ok(RecoveredObject {
        global_error: global_error(&solid, &all),
        solid,
        segments: recovered,
    })
}

#[cfg(test)]
mod tests {
    use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
    use rand::rngs::StdRng;
    use rand::{Rng, SeedableRng};
    use rand_distr::{Distribution, Normal};

    use super::*;
    use crate::geometry::supershape::deform::{Deformation, Deformations};
    use crate::geometry::supershape::distance::SolidDistance;
    use crate::geometry::supershape::formula::Superformula;
    use crate::geometry::supershape::shape::Supershape;

    fn placed(shape: Supershape, place: Isometry3<f64>) -> Node {
        Node::supershape(shape, Deformations(vec![Deformation::Rigid(place)]))
    }

    fn superellipse(m: f64, n: f64) -> Superformula {
        Superformula::new(m, n, n, n, 1.0, 1.0).unwrap()
    }

    /// A flange with a boss: a rounded block 60 x 40 x 16 mm and a round boss of radius 9 mm standing 8 mm out of
    /// its top, turned and moved. Each is scanned where it is the part's outside (the block's top is not scanned
    /// under the boss, the boss not inside the block), as a segmentation would give them, with 0.02 mm noise.
    /// The union of the recovered segments holds every point within a few hundredths of a mm, and tells inside
    /// from outside as the true part does (the boss included) at 99.5% of points drawn around it.
    #[test]
    fn a_segmented_part_is_the_union_of_its_recovered_segments() {
        let turn = Isometry3::from_parts(
            Translation3::new(20.0, -10.0, 5.0),
            UnitQuaternion::from_euler_angles(0.3, -0.2, 0.7),
        );
        let block = Supershape {
            r1: superellipse(4.0, 10.0),
            r2: superellipse(4.0, 10.0),
            scale: [30.0, 20.0, 8.0],
        };
        let boss = Supershape {
            r1: superellipse(4.0, 2.0),
            r2: superellipse(4.0, 8.0),
            scale: [9.0, 9.0, 7.0],
        };
        let block_place = turn;
        let boss_place = turn * Isometry3::translation(5.0, 2.0, 9.0);
        let (block_node, boss_node) = (placed(block, block_place), placed(boss, boss_place));
        let mut rng = StdRng::seed_from_u64(63);
        let noise = Normal::new(0.0, 0.02).unwrap();
        let mut scan = |shape: &Supershape, place: &Isometry3<f64>, other: &Node, count: usize| {
            shape
                .surface_points(count)
                .iter()
                .map(|p| place * p)
                .filter(|p| other.value(p) < 0.0)
                .map(|p| p + Vector3::from_fn(|_, _| noise.sample(&mut rng)))
                .collect::<Vec<_>>()
        };
        let segments = vec![
            SegmentPoints {
                label: "block".into(),
                points: scan(&block, &block_place, &boss_node, 2500),
            },
            SegmentPoints {
                label: "boss".into(),
                points: scan(&boss, &boss_place, &block_node, 1500),
            },
        ];
        let mut heard = Vec::new();
        let object = recover_segments(&segments, &RecoveryOptions::default(), &mut |k, s| {
            heard.push((k, s.label.clone()))
        })
        .unwrap();
        assert_eq!(heard, [(0, "block".to_string()), (1, "boss".to_string())]);
        assert_eq!(object.segments.len(), 2);
        assert_eq!(object.segments[1].label, "boss");
        let distance = SolidDistance::new(&object.solid);
        let all: Vec<Point3<f64>> = segments.iter().flat_map(|s| s.points.clone()).collect();
        let distances: Vec<f64> = all
            .iter()
            .map(|p| distance.foot(p).expect("a distance").distance_mm.abs())
            .collect();
        let rms = (distances.iter().map(|d| d * d).sum::<f64>() / all.len() as f64).sqrt();
        assert!(rms < 0.06, "RMS distance {rms} mm");
        let truth = Node::boolean(
            Boolean::Union,
            RFunction::P(2),
            block_node,
            boss_node.clone(),
        );
        let mut agree = 0;
        let mut in_boss = 0;
        let trials = 4000;
        for _ in 0..trials {
            let p = turn
                * Point3::new(
                    rng.gen_range(-34.0..34.0),
                    rng.gen_range(-24.0..24.0),
                    rng.gen_range(-12.0..20.0),
                );
            let inside = truth.value(&p) > 0.0;
            agree += usize::from(inside == (object.solid.value(&p) > 0.0));
            in_boss += usize::from(
                inside
                    && boss_node.value(&p) > 0.0
                    && block.radial(&(block_place.inverse() * p)) < 0.0,
            );
        }
        println!(
            "segmented flange: RMS distance {rms:.4} mm, {agree} of {trials} inside/outside as the part \
             ({in_boss} in the boss), global error {:.3e} mm^3",
            object.global_error
        );
        assert!(in_boss > 50, "the draw reaches the boss: {in_boss}");
        assert!(
            agree as f64 >= 0.995 * trials as f64,
            "{agree} of {trials} agree"
        );
        assert!(object.global_error.is_finite() && object.global_error > 0.0);
        // A segment too small to fit is refused by name before any segment's recovery starts.
        let mut started = 0;
        let refused = recover_segments(
            &[
                segments[0].clone(),
                SegmentPoints {
                    label: "burr".into(),
                    points: all[..10].to_vec(),
                },
            ],
            &RecoveryOptions::default(),
            &mut |_, _| started += 1,
        );
        assert_eq!(started, 0);
        assert_eq!(
            refused.unwrap_err().to_string(),
            "segment 'burr': 10 points cannot fix a supershape; give at least 60 points spread over the part's surface"
        );
    }
}
