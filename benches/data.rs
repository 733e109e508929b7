//! Bench inputs, made from public data: the quartic seed 003 publishes for profile 3, sampled with seeded 2 um
//! noise along the normal.

use nalgebra::Vector2;
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
