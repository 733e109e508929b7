//! Bench inputs, made from public data: the quartic seed 003 publishes for profile 3, and a smooth closed 3-D
//! surface, both sampled with seeded 2 um noise along the normal.

use nalgebra::{Vector2, Vector3};
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use zeroset::geometry::implicit::{Implicit, IpModel};
use zeroset::geometry::published::seed_003_profile;
use zeroset::geometry::sampling::project_to_zero_set;
use zeroset::geometry::trace::{resample_closed, trace_closed_curve};

pub fn profile_3() -> IpModel<2> {
    seed_003_profile(3).expect("published")
}

/// `count` points in scan order around profile 3, `offset` mm along the normal, with 2 um noise.
pub fn profile_3_scan(count: usize, offset: f64) -> Vec<Vector2<f64>> {
    let model = profile_3();
    let start =
        project_to_zero_set(&model, &Vector2::new(100.0, 320.0), 50.0).expect("on the section");
    let section = trace_closed_curve(&model, &start, 0.05, 1_000_000).expect("closed section");
    let mut rng = rand::rngs::StdRng::seed_from_u64(3);
    let noise = Normal::new(0.0, 0.002).expect("sigma");
    resample_closed(&section, count)
        .into_iter()
        .map(|p| p + model.value_gradient(&p).1.normalize() * (offset + noise.sample(&mut rng)))
        .collect()
}

/// `count` points on r(theta, phi) = 50 (1 + 0.1 sin 3 theta cos 2 phi) mm, with 2 um noise along the radius.
pub fn blob(count: usize) -> Vec<Vector3<f64>> {
    let mut rng = rand::rngs::StdRng::seed_from_u64(6);
    let noise = Normal::new(0.0, 0.002).expect("sigma");
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..count)
        .map(|i| {
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / count as f64;
            let theta = z.acos();
            let phi = golden * i as f64;
            let r = 50.0 * (1.0 + 0.1 * (3.0 * theta).sin() * (2.0 * phi).cos())
                + noise.sample(&mut rng);
            Vector3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), z) * r
        })
        .collect()
}
