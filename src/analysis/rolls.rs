//! The contacts of the ball rolling round a sharp edge in a master's teach scan: which they are, and how the
//! reference takes them (thinned for the nominals, the apex for the faces' fits; the polynomial takes them all).

use nalgebra::{Point3, Vector3};

/// A taught nominal this close to a sharp edge's apex, in its profile's plane (y, z; mm), is one of the contacts of
/// the ball rolling round the edge: the compensation puts those within about 12 um of the apex.
const ROLL_REACH_MM: f64 = 0.1;

/// A roll's contacts are thinned to steps of at least this turn of their normals.
const ROLL_TURN_DEGREES: f64 = 45.0;

/// Whether a scan point (part frame, its profile's plane x = const) lies within [`ROLL_REACH_MM`] of one of the
/// sharp edges' apexes (in that plane, (y, z)).
pub(crate) fn rolling(point: &Point3<f64>, apexes: &[[f64; 2]]) -> bool {
    apexes
        .iter()
        .any(|a| (a[0] - point.y).hypot(a[1] - point.z) <= ROLL_REACH_MM)
}

/// Which of a master scan's points (in scan order, with their normals; part frame, the profile's plane x =
/// const) to thin to nominals: all but the contacts of each roll round a sharp edge (apexes in the profile's
/// plane, (y, z)), which are kept only a step of at least [`ROLL_TURN_DEGREES`] apart, the roll's first and last
/// always. The scan itself is kept whole with its job.
///
/// Why: a teach scan steps round a sharp edge as finely as round a nose (`round_edge_max_angle_deg`), 60 or more
/// contacts at one apex. As nominals, an instance's curve scan cuts each taught step of a roll evenly into the
/// scan's `max_angle_deg` (`plan::at_density`): in 1 mm steps round a 1 mm ball (57 deg a point) the cuts were
/// even, 9.5 deg; taught every 10 deg, steps of 10 and 5 deg alternated, and an instance lying 0.88 mm below the
/// master then rolled 1-2 deg a point at first, too little for the compensation to see the roll: its contacts 50
/// um apart and its chord 37-43 um long (BENCHMARKS.md, issue 16).
pub(crate) fn without_dense_rolls(
    points: &[Point3<f64>],
    normals: &[Vector3<f64>],
    apexes: &[[f64; 2]],
) -> Vec<usize> {
    let rolling = |i: usize| rolling(&points[i], apexes);
    let min_cosine = ROLL_TURN_DEGREES.to_radians().cos();
    let mut kept = Vec::with_capacity(points.len());
    // The last point kept in the roll under way, if one is.
    let mut roll_kept: Option<usize> = None;
    for i in 0..points.len() {
        if !rolling(i) {
            roll_kept = None;
            kept.push(i);
            continue;
        }
        let last_of_roll = i + 1 == points.len() || !rolling(i + 1);
        let turned_enough = roll_kept
            .is_none_or(|k| normals[k].normalize().dot(&normals[i].normalize()) <= min_cosine);
        if last_of_roll || turned_enough {
            kept.push(i);
            roll_kept = Some(i);
        }
    }
    kept
}

/// A master scan (as [`without_dense_rolls`] takes it) with each roll round a sharp edge replaced by one point,
/// the edge's apex (as [`find_sharp_edges`](super::edges::find_sharp_edges) found it: the mean of the contacts
/// that stayed put while the normal turned), with the contacts' mean normal: what the faces are fitted to.
///
/// Why: the faces already pass through the edge (the sharp end's point weighs 26 times in their fits on a 16 deg
/// edge, more on a thinner one). A roll of 60 contacts within the compensation's 12 um of the apex, split between
/// the two faces, outweighed their other points: r400's faces read the trailing edge 25 um thick, r300's fitted
/// their points 3.4 um RMS. The apex, not the mean of every point within [`ROLL_REACH_MM`]: points sampled along
/// the faces up to a sharp edge (no ball rolling) lie within that reach too, and their mean lies inside the edge.
pub(crate) fn with_rolls_merged(
    points: &[Point3<f64>],
    normals: &[Vector3<f64>],
    apexes: &[[f64; 2]],
) -> (Vec<Point3<f64>>, Vec<Vector3<f64>>) {
    let nearest_apex = |p: &Point3<f64>| {
        apexes
            .iter()
            .min_by(|a, b| {
                let off = |a: &[f64; 2]| (a[0] - p.y).hypot(a[1] - p.z);
                off(a).total_cmp(&off(b))
            })
            .copied()
    };
    let mut merged_points = Vec::with_capacity(points.len());
    let mut merged_normals = Vec::with_capacity(points.len());
    let mut i = 0;
    while i < points.len() {
        let apex = nearest_apex(&points[i]).filter(|_| rolling(&points[i], apexes));
        let Some(apex) = apex else {
            merged_points.push(points[i]);
            merged_normals.push(normals[i]);
            i += 1;
            continue;
        };
        let mut end = i + 1;
        while end < points.len() && rolling(&points[end], apexes) {
            end += 1;
        }
        let x = points[i..end].iter().map(|p| p.x).sum::<f64>() / (end - i) as f64;
        let normal = normals[i..end]
            .iter()
            .fold(Vector3::zeros(), |sum, n| sum + n.normalize());
        merged_points.push(Point3::new(x, apex[0], apex[1]));
        merged_normals.push(if normal.norm() > 0.0 {
            normal.normalize()
        } else {
            normals[i]
        });
        i = end;
    }
    (merged_points, merged_normals)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_rolls_contacts_are_thinned_to_45_degree_steps_and_the_faces_are_not() {
        // A face along y up to a sharp edge at (y, z) = (10, 0), a roll of 19 contacts at the apex turning 180 deg
        // by 10 deg, and the other face back: the roll keeps its first, every fifth (50 deg on) and its last.
        let mut points: Vec<Point3<f64>> =
            (0..10).map(|k| Point3::new(50.0, k as f64, 0.01)).collect();
        let mut normals: Vec<Vector3<f64>> = vec![Vector3::z() * 2.0; 10];
        for k in 0..19 {
            let a = (k as f64 * 10.0).to_radians();
            points.push(Point3::new(50.0, 10.0 + 0.005 * a.sin(), 0.005 * a.cos()));
            normals.push(Vector3::new(0.0, a.sin(), a.cos()));
        }
        points.extend((0..10).map(|k| Point3::new(50.0, 9.0 - k as f64, -0.01)));
        normals.extend(vec![-Vector3::z(); 10]);
        let kept = without_dense_rolls(&points, &normals, &[[10.0, 0.0]]);
        let expected: Vec<usize> = (0..10)
            .chain([0, 5, 10, 15, 18].map(|k| 10 + k))
            .chain(29..39)
            .collect();
        assert_eq!(kept, expected);
        // No apex: every point is kept.
        assert_eq!(
            without_dense_rolls(&points, &normals, &[]),
            (0..39).collect::<Vec<_>>()
        );
    }

    #[test]
    fn a_roll_becomes_its_edges_apex_and_the_faces_are_kept_as_they_are() {
        // Two faces meeting at (y, z) = (10, 0): four points on each, and a roll of three contacts between them
        // (normals up, along +y, down): those become one point at the apex with the normal along +y.
        let mut points: Vec<Point3<f64>> = (0..4)
            .map(|k| Point3::new(50.0, k as f64 * 2.0, 0.05))
            .collect();
        let mut normals: Vec<Vector3<f64>> = vec![Vector3::z(); 4];
        points.extend(
            [[10.0, 0.006], [10.009, 0.0], [10.0, -0.006]].map(|[y, z]| Point3::new(50.0, y, z)),
        );
        normals.extend([Vector3::z(), Vector3::y() * 3.0, -Vector3::z()]);
        points.extend((0..4).map(|k| Point3::new(50.0, 6.0 - k as f64 * 2.0, -0.05)));
        normals.extend(vec![-Vector3::z(); 4]);
        let (merged, merged_normals) = with_rolls_merged(&points, &normals, &[[10.0, 0.0]]);
        assert_eq!(merged.len(), 9);
        assert_eq!(&merged[..4], &points[..4]);
        assert_eq!(&merged[5..], &points[7..]);
        assert_eq!(merged[4], Point3::new(50.0, 10.0, 0.0));
        assert!(
            (merged_normals[4] - Vector3::y()).norm() < 1e-12,
            "{}",
            merged_normals[4]
        );
        assert_eq!(&merged_normals[5..], &normals[7..]);
        // No apex: nothing is merged.
        assert_eq!(with_rolls_merged(&points, &normals, &[]).0, points);
    }
}
