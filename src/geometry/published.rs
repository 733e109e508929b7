//! The quartics that seed 003 publishes for profiles 1, 3 and 5 of the master blade A, as printed (coefficients
//! for y, z in centimetres), re-expressed in millimetres. Ground truth for tests and the offline example.

use super::implicit::{Frame, IpModel};
use super::poly::Poly;

/// Terms as printed in seed 003 section 3: ((power of y, power of z), coefficient), in cm.
type Terms = [((u8, u8), f64); 15];

const PROFILE_1: Terms = [
    ((4, 0), 1.0),
    ((3, 1), -0.088),
    ((2, 2), 2.083),
    ((1, 3), -4.805),
    ((0, 4), 1.741),
    ((3, 0), 14.531),
    ((2, 1), -15.653),
    ((1, 2), -17.377),
    ((0, 3), -2.704),
    ((2, 0), -87.629),
    ((1, 1), 4.574),
    ((0, 2), -201.26),
    ((1, 0), -950.35),
    ((0, 1), 138.09),
    ((0, 0), 5146.7),
];

const PROFILE_3: Terms = [
    ((4, 0), 1.0),
    ((3, 1), -1.038),
    ((2, 2), 3.041),
    ((1, 3), -3.765),
    ((0, 4), 1.922),
    ((3, 0), 15.833),
    ((2, 1), -31.942),
    ((1, 2), 29.537),
    ((0, 3), -25.706),
    ((2, 0), -102.36),
    ((1, 1), 29.709),
    ((0, 2), -187.493),
    ((1, 0), -1522.1),
    ((0, 1), 1811.3),
    ((0, 0), 9445.3),
];

const PROFILE_5: Terms = [
    ((4, 0), 1.0),
    ((3, 1), 1.453),
    ((2, 2), -7.594),
    ((1, 3), 6.431),
    ((0, 4), 0.97),
    ((3, 0), -17.437),
    ((2, 1), 29.452),
    ((1, 2), 7.7),
    ((0, 3), -26.845),
    ((2, 0), 371.463),
    ((1, 1), -736.448),
    ((0, 2), -20.391),
    ((1, 0), -3088.1),
    ((0, 1), 2226.6),
    ((0, 0), 7559.2),
];

/// The published quartic of profile 1, 3 or 5 of blade A in mm (F > 0 outside). `None` for the profiles the
/// paper does not print (2 and 4).
pub fn seed_003_profile(number: u8) -> Option<IpModel<2>> {
    let terms = match number {
        1 => &PROFILE_1,
        3 => &PROFILE_3,
        5 => &PROFILE_5,
        _ => return None,
    };
    let mut poly = Poly::<2>::zero(4);
    for &((i, j), c) in terms {
        let index = poly.basis().index_of(&[i, j]).expect("quartic terms");
        // F_mm(p) = F_cm(p / 10): a term of total degree k scales by 10^-k.
        poly.coeffs_mut()[index] = c * 10f64.powi(-((i + j) as i32));
    }
    Some(IpModel {
        frame: Frame::identity(),
        poly,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::implicit::Implicit;
    use nalgebra::Vector2;

    #[test]
    fn profile_3_encloses_material_where_figure_2_shows_the_blade() {
        let model = seed_003_profile(3).unwrap();
        // Inside the section (about y 0..200 mm, z 55..320 mm in the paper's frame) F < 0; far away F > 0.
        assert!(model.value(&Vector2::new(100.0, 200.0)) < 0.0);
        assert!(model.value(&Vector2::new(500.0, 500.0)) > 0.0);
        assert!(seed_003_profile(2).is_none());
        // The leading coefficient y^4 is 1 per cm^4 = 1e-4 per mm^4; the constant stays 9445.3.
        assert_eq!(model.poly.coeff(&[4, 0]), 1e-4);
        assert_eq!(model.poly.coeff(&[0, 0]), 9445.3);
    }
}
