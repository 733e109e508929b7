use nalgebra::Vector2;

use super::*;
use crate::analysis::deviation::ProfileGauge;
use crate::analysis::test_profiles::{taught_ellipses, Ellipse, SETTINGS, TAUGHT_POINTS};
use crate::geometry::implicit::Implicit;

fn masters() -> Vec<MasterProfile> {
    Ellipse::stack()
        .iter()
        .map(|e| e.master_profile(TAUGHT_POINTS))
        .collect()
}

#[test]
fn a_taught_reference_is_a_stack_that_fits_the_ellipses_positive_outside() {
    let reference = taught_ellipses();
    assert_eq!(
        (
            reference.format.as_str(),
            reference.version,
            reference.units.as_str()
        ),
        (FORMAT, VERSION, "mm")
    );
    assert_eq!(reference.part, "ellipse-blade");
    humantime::parse_rfc3339(&reference.taught_at).expect("taught_at is RFC 3339 UTC");
    let ReferenceModel::Stack { profiles } = &reference.model.model else {
        panic!("not a stack: {:?}", reference.model.model);
    };
    assert!(stack_of(profiles).is_ok());
    for ((model, taught), ellipse) in profiles
        .iter()
        .zip(&reference.profiles)
        .zip(Ellipse::stack())
    {
        assert_eq!((model.x, taught.x_mm), (ellipse.x, ellipse.x));
        assert_eq!(taught.name, ellipse.name());
        let stats = model.fitted.fit.as_ref().expect("statistics are kept");
        assert_eq!(stats.points, TAUGHT_POINTS);
        assert!(stats.rms_distance_mm < 1e-3, "{stats:?}");
        // Outward normals make the model positive outside: just beyond the end of the major axis, and negative
        // at the centre.
        let tip = ellipse.offset_point(0.0, 0.5);
        let centre = ellipse.offset_point(0.0, -0.5);
        let ip = &model.fitted.ip;
        assert!(ip.value(&Vector2::new(tip.y, tip.z)) > 0.0);
        assert!(ip.value(&Vector2::new(centre.y, centre.z)) < 0.0);
    }
}

#[test]
fn a_saved_reference_loads_as_it_was_and_measures_the_same() {
    let reference = taught_ellipses();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("reference.json");
    reference.save(&path).unwrap();
    let loaded = Reference::load(&path).unwrap();
    assert_eq!(&loaded, reference, "every number round-trips exactly");
    let point = Ellipse::stack()[1].offset_point(2.0, 0.25);
    let before = ProfileGauge::all(reference)[1]
        .scan()
        .measure(&point)
        .unwrap();
    let after = ProfileGauge::all(&loaded)[1]
        .scan()
        .measure(&point)
        .unwrap();
    assert_eq!(before, after);
}

#[test]
fn a_reference_file_that_does_not_match_is_refused_by_what_is_wrong() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad-reference.json");
    let refuse = |change: &dyn Fn(&mut Reference)| {
        let mut reference = taught_ellipses().clone();
        change(&mut reference);
        reference.save(&path).unwrap();
        Reference::load(&path).unwrap_err().to_string()
    };
    let error = refuse(&|r| r.version = 1);
    assert!(
        error.contains("bad-reference.json") && error.contains("version 1"),
        "{error}"
    );
    let error = refuse(&|r| r.units = "inch".into());
    assert!(error.contains("units 'inch'"), "{error}");
    let error = refuse(&|r| r.profiles[3].x_mm = 410.0);
    assert!(
        error.contains("profile 3 'x400'") && error.contains("x = 400 mm"),
        "{error}"
    );
    let error = refuse(&|r| {
        r.profiles.pop();
    });
    assert!(
        error.contains("5 profiles but the reference lists 4"),
        "{error}"
    );
    let error = refuse(&|r| {
        if let ReferenceModel::Stack { profiles } = &mut r.model.model {
            profiles[0].fitted.ip.frame.scale = 0.0;
        }
    });
    assert!(
        error.contains("profile 0 'x100'") && error.contains("scale is 0"),
        "{error}"
    );
    let error = refuse(&|r| {
        r.settings = ReferenceSettings::Supershape {
            symmetry: None,
            nominal_spacing_mm: 2.0,
        }
    });
    assert!(error.contains("settings.kind \"supershape\""), "{error}");
    // Nominals the scans cannot follow: a zero normal, one that is not unit, none at all.
    let error = refuse(&|r| r.profiles[2].nominals[17].normal = [0.0, 0.0, 0.0]);
    assert!(
        error.contains("bad-reference.json")
            && error.contains("profile 2 'x300' (x = 300 mm), nominal 17: normal [0.0, 0.0, 0.0] is not a unit vector (length 0)")
            && error.ends_with("teach the reference again"),
        "{error}"
    );
    let error = refuse(&|r| r.profiles[0].nominals[3].normal = [0.0, 0.6, 0.6]);
    assert!(
        error.contains(
            "profile 0 'x100' (x = 100 mm), nominal 3: normal [0.0, 0.6, 0.6] is not a unit vector"
        ),
        "{error}"
    );
    let error = refuse(&|r| r.profiles[4].nominals.clear());
    assert!(
        error.contains("profile 4 'x500' (x = 500 mm) has no nominal points"),
        "{error}"
    );
    std::fs::write(&path, "{\"format\": \"zeroset-reference\"").unwrap();
    let error = Reference::load(&path).unwrap_err();
    assert!(matches!(error, ReferenceFileError::Parse { .. }), "{error}");
    let missing = dir.path().join("missing.json");
    let error = Reference::load(&missing).unwrap_err().to_string();
    assert!(error.contains("missing.json"), "{error}");
}

#[test]
fn nominals_start_and_end_at_the_scan_and_stay_within_the_spacing() {
    let reference = taught_ellipses();
    for (taught, master) in reference.profiles.iter().zip(masters()) {
        let nominals = &taught.nominals;
        assert_eq!(nominals[0].point, <[f64; 3]>::from(master.points[0].coords));
        let last = master.points[master.points.len() - 1];
        assert_eq!(
            nominals[nominals.len() - 1].point,
            <[f64; 3]>::from(last.coords)
        );
        for pair in nominals.windows(2) {
            let step = (Vector3::from(pair[1].point) - Vector3::from(pair[0].point)).norm();
            assert!(
                step <= SETTINGS.nominal_spacing_mm(),
                "{step} mm between {pair:?}"
            );
        }
        for n in nominals {
            assert!((Vector3::from(n.normal).norm() - 1.0).abs() < 1e-12);
            assert!(
                n.normal[0] != 0.0,
                "the surface normal keeps its lean along x"
            );
        }
        // The perimeters are 150 to 300 mm: a 5 mm spacing keeps tens of points, not all 240.
        assert!(nominals.len() < TAUGHT_POINTS / 2, "{}", nominals.len());
    }
}

#[test]
fn a_profile_with_too_few_points_names_itself() {
    let mut profiles = masters();
    profiles[2].points.truncate(6);
    profiles[2].normals.truncate(6);
    let error = teach("p", &profiles, &SETTINGS).unwrap_err();
    assert!(
        matches!(&error, TeachError::Fit { name, x_mm, problem: FitError::TooFewPoints { got: 6, .. } }
            if name == "x300" && *x_mm == 300.0),
        "{error:?}"
    );
    let message = error.to_string();
    assert!(
        message.contains("'x300'") && message.contains("x = 300 mm"),
        "{message}"
    );
}

#[test]
fn teaching_refuses_what_cannot_make_a_reference() {
    let profiles = masters();
    assert_eq!(
        teach("p", &profiles[..1], &SETTINGS).unwrap_err(),
        TeachError::TooFewProfiles { got: 1 }
    );
    let mut twins = profiles[..2].to_vec();
    twins[1].name = twins[0].name.clone();
    assert!(matches!(
        teach("p", &twins, &SETTINGS).unwrap_err(),
        TeachError::DuplicateName { name } if name == "x100"
    ));
    let mut along_x = profiles[..2].to_vec();
    along_x[1].normals[7] = Vector3::new(1.0, 0.0, 0.0);
    assert!(matches!(
        teach("p", &along_x, &SETTINGS).unwrap_err(),
        TeachError::NormalOutOfPlane { index: 7, .. }
    ));
    let mut short = profiles[..2].to_vec();
    short[0].normals.pop();
    assert!(matches!(
        teach("p", &short, &SETTINGS).unwrap_err(),
        TeachError::NormalCount {
            points: 240,
            normals: 239,
            ..
        }
    ));
    let mut same_plane = profiles[..2].to_vec();
    same_plane[1].x_mm = same_plane[0].x_mm;
    same_plane[1].name = "again".into();
    assert!(matches!(
        teach("p", &same_plane, &SETTINGS).unwrap_err(),
        TeachError::Stack(StackError::SamePosition(..))
    ));
    let no_spacing = ReferenceSettings::ImplicitPolynomial {
        degree: 4,
        method: FitMethod::Orthogonal,
        nominal_spacing_mm: 0.0,
    };
    assert!(matches!(
        teach("p", &profiles, &no_spacing).unwrap_err(),
        TeachError::BadSpacing { .. }
    ));
}

/// The part files' bound on the degree is one the teach can do: above it the fit panicked.
#[test]
fn the_highest_degree_a_part_file_may_give_teaches() {
    let settings = ReferenceSettings::ImplicitPolynomial {
        degree: crate::config::part::MAX_REFERENCE_DEGREE,
        method: FitMethod::Orthogonal,
        nominal_spacing_mm: 5.0,
    };
    let reference = teach("ellipse-blade", &masters(), &settings).expect("degree 14 teaches");
    let ReferenceModel::Stack { profiles } = &reference.model.model else {
        panic!("not a stack");
    };
    assert!(profiles.iter().all(|p| p.fitted.ip.poly.degree() == 14));
}
