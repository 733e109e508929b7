//! A brake hub after seed 000 fig. 5 (54 supershapes, 31 Booleans there): a test and benchmark
//! fixture for meshing and classifying a tree of realistic size, not a part drawing. 54 primitives
//! (a rim with its relief, a flange lip, the boss and its collar, twelve twisted or tapered ribs,
//! four bent balance lobes; the bore, two keyways, twelve bolt holes, six stud holes, twelve
//! radial holes through the rim), joined by 53 Boolean nodes, all in millimetres, z the hub's axis.

use std::f64::consts::{FRAC_PI_2, PI};

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

use super::super::csg::{Node, Solid};
use super::super::deform::{Deformation, Deformations};
use super::super::formula::Superformula;
use super::super::rfunc::{Boolean, RFunction};
use super::super::shape::Supershape;

/// The same R-function at every node: R_p with p = 2, differentiable off the origin (seed 000).
const RF: RFunction = RFunction::P(2);

/// The hub as a solid.
pub fn brake_hub() -> Solid {
    let mut body = vec![
        Node::boolean(
            Boolean::Difference,
            RF,
            cylinder(60.0, 7.0, at(0.0, 0.0, 3.0)),
            cylinder(54.0, 3.5, at(0.0, 0.0, 8.5)),
        ),
        cylinder(66.0, 2.0, at(0.0, 0.0, -1.0)),
        cylinder(26.0, 15.0, at(0.0, 0.0, 9.0)),
        cylinder(32.0, 2.0, at(0.0, 0.0, 21.0)),
    ];
    for k in 0..12 {
        let angle = k as f64 * PI / 6.0;
        let (x, y) = (40.0 * angle.cos(), 40.0 * angle.sin());
        let shaping = if k % 2 == 0 {
            Deformation::Twist { rate: 0.03 }
        } else {
            Deformation::Taper { kx: 0.0, ky: -0.05 }
        };
        body.push(Node::cuboid(
            [16.0, 2.0, 4.0],
            Deformations(vec![shaping, placed(x, y, 8.0, angle)]),
        ));
    }
    for k in 0..4 {
        let angle = k as f64 * FRAC_PI_2;
        let lobe = Supershape {
            r1: Superformula::new(5.0, 2.0, 7.0, 7.0, 1.0, 1.0).expect("valid lobe profile"),
            r2: Superformula::circle(),
            scale: [1.0, 1.0, 1.0],
        };
        body.push(Node::supershape(
            lobe,
            Deformations(vec![
                Deformation::Scale([3.0, 3.0, 3.0]),
                Deformation::Bend { curvature: 0.02 },
                placed(45.0 * angle.cos(), 45.0 * angle.sin(), -4.0, angle),
            ]),
        ));
    }
    let mut holes = vec![cylinder(12.0, 20.0, at(0.0, 0.0, 9.0))];
    for side in [-1.0, 1.0] {
        holes.push(Node::cuboid([2.5, 2.0, 18.0], at(12.0 * side, 0.0, 9.0)));
    }
    for k in 0..12 {
        let angle = (k as f64 + 0.5) * PI / 6.0;
        holes.push(cylinder(
            3.5,
            8.0,
            at(40.0 * angle.cos(), 40.0 * angle.sin(), 1.0),
        ));
        // A radial hole through the rim wall: the cylinder's axis turned from z to the radius.
        let radial = Isometry3::from_parts(
            Translation3::new(57.0 * angle.cos(), 57.0 * angle.sin(), 7.5),
            UnitQuaternion::from_axis_angle(&Vector3::z_axis(), angle)
                * UnitQuaternion::from_axis_angle(&Vector3::y_axis(), FRAC_PI_2),
        );
        holes.push(cylinder(
            1.5,
            6.0,
            Deformations(vec![Deformation::Rigid(radial)]),
        ));
    }
    for k in 0..6 {
        let angle = k as f64 * PI / 3.0 + PI / 6.0;
        holes.push(cylinder(
            2.5,
            18.0,
            at(19.0 * angle.cos(), 19.0 * angle.sin(), 9.0),
        ));
    }
    Solid::new(Node::boolean(
        Boolean::Difference,
        RF,
        union_all(body),
        union_all(holes),
    ))
}

/// A cylinder of the given radius and half height along the canonical z axis: a circle in theta,
/// a near-square (exponents 40) in phi, so the caps are flat and the rims sharp.
fn cylinder(radius: f64, half_height: f64, place: Deformations) -> Node {
    let square = Superformula::new(4.0, 40.0, 40.0, 40.0, 1.0, 1.0).expect("valid profile");
    Node::supershape(
        Supershape {
            r1: Superformula::circle(),
            r2: square,
            scale: [radius, radius, half_height],
        },
        place,
    )
}

fn at(x: f64, y: f64, z: f64) -> Deformations {
    Deformations(vec![Deformation::Rigid(Isometry3::translation(x, y, z))])
}

/// Moved to (x, y, z) and turned by `angle` about z.
fn placed(x: f64, y: f64, z: f64, angle: f64) -> Deformation {
    Deformation::Rigid(Isometry3::from_parts(
        Translation3::new(x, y, z),
        UnitQuaternion::from_axis_angle(&Vector3::z_axis(), angle),
    ))
}

/// A balanced tree of unions.
fn union_all(mut nodes: Vec<Node>) -> Node {
    if nodes.len() == 1 {
        return nodes.remove(0);
    }
    let right = nodes.split_off(nodes.len() / 2);
    Node::boolean(Boolean::Union, RF, union_all(nodes), union_all(right))
}

#[cfg(test)]
mod tests {
    use super::super::{polygonise, MeshParams};
    use super::*;
    use nalgebra::Point3;

    #[test]
    fn the_hub_has_the_seeds_size_and_its_holes() {
        let hub = brake_hub();
        assert_eq!(hub.root().counts(), (54, 53));
        // Material in the boss wall, the rib, the rim and the lip; air in the bore, a bolt hole,
        // a stud hole, a radial hole and the relief above the web.
        for p in [
            (20.0, 0.0, 9.0),
            (40.0, 0.0, 10.0),
            (57.0, 2.0, 3.0),
            (63.0, 0.0, -1.0),
        ] {
            assert!(hub.contains(&Point3::new(p.0, p.1, p.2)), "{p:?}");
        }
        let bolt = (PI / 12.0).sin_cos();
        let stud = (PI / 6.0).sin_cos();
        for p in [
            (0.0, 0.0, 9.0),
            (40.0 * bolt.1, 40.0 * bolt.0, 0.0),
            (19.0 * stud.1, 19.0 * stud.0, 9.0),
            (57.0 * bolt.1, 57.0 * bolt.0, 7.5),
            (45.0, 10.0, 8.0),
        ] {
            assert!(!hub.contains(&Point3::new(p.0, p.1, p.2)), "{p:?}");
        }
    }

    #[test]
    fn the_hub_meshes_closed_with_one_handle_per_through_hole() {
        let hub = brake_hub();
        let params = MeshParams::with_cell(1.0);
        let mesh = polygonise(&hub, &params).unwrap();
        assert!(mesh.is_closed());
        // Through holes: the bore (with its keyways), 12 bolt holes, 6 stud holes and 12 radial
        // holes into the open relief. Genus 31: V - E + F = 2 - 62.
        assert_eq!(mesh.euler_characteristic(), -60);
        let worst = mesh
            .vertices
            .iter()
            .map(|v| hub.value(v).abs())
            .fold(0.0, f64::max);
        assert!(worst < params.epsilon, "{worst}");
    }
}
