//! Bench inputs from the demo propeller's simulator (config/sims/propeller.toml): scans of blade A's sections
//! x = const with seeded 2 um noise along the normal, as the station's master scans see them.

use std::path::Path;

use nalgebra::{Point3, Vector3};
use rand::rngs::StdRng;
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use zeroset::analysis::reference::MasterProfile;
use zeroset_sim::config::SimConfig;
use zeroset_sim::part::Plane;

/// Blade A's section x = `x_mm`, `count` points round it (one per mm of its length when `None`), part frame.
pub fn section_scan(x_mm: f64, count: Option<usize>, rng: &mut StdRng) -> MasterProfile {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let sim = SimConfig::load(&root.join("config/sims/propeller.toml")).expect("sim config");
    let part = sim.parts["propeller"].build().expect("propeller");
    let noise = Normal::new(0.0, 0.002).expect("sigma");
    let plane = Plane {
        point: Point3::new(x_mm, 0.0, 0.0),
        normal: Vector3::x(),
    };
    let section = part.section(&plane).expect("the plane cuts blade A");
    let count = count.unwrap_or_else(|| {
        let dense = section.curve.dense(4000);
        let length: f64 = (0..dense.len())
            .map(|i| (dense[(i + 1) % dense.len()].point - dense[i].point).norm())
            .sum();
        length.round() as usize
    });
    let frame = section.frame;
    let (points, normals) = section
        .curve
        .dense(count)
        .iter()
        .map(|c| {
            let p = c.point.coords + c.normal * noise.sample(rng);
            (
                frame.world(p.x, p.y, 0.0),
                frame.world_dir(c.normal.x, c.normal.y, 0.0),
            )
        })
        .unzip();
    MasterProfile {
        name: format!("r{x_mm}"),
        x_mm,
        points,
        normals,
    }
}

/// The master's scan of the demo propeller: the five sections of config/parts/propeller.toml at the part's scan
/// step (1 mm).
pub fn master_profiles() -> Vec<MasterProfile> {
    let mut rng = StdRng::seed_from_u64(4412);
    [100.0, 200.0, 300.0, 400.0, 500.0]
        .iter()
        .map(|&x| section_scan(x, None, &mut rng))
        .collect()
}
