use super::*;

const CLASSES: [Iso484Class; 4] = [
    Iso484Class::S,
    Iso484Class::I,
    Iso484Class::II,
    Iso484Class::III,
];

/// The verdict on `measured` against `nominal` for `parameter` in `class`.
fn verdict(
    class: Iso484Class,
    parameter: Parameter,
    nominal: f64,
    measured: f64,
) -> ParameterVerdict {
    let mut value = ParameterValue::of(nominal, measured);
    ParameterTolerances::new(Some(class), ParameterRules::default()).judge(parameter, &mut value);
    assert_eq!(
        value.tolerance.unwrap().from,
        ToleranceSource::Iso484(class)
    );
    value.verdict.unwrap()
}

/// Just inside and just outside each limit (by 0.01 of the parameter's unit): `limits` (lower, upper) worked out
/// by hand from the class table.
fn assert_limits(
    class: Iso484Class,
    parameter: Parameter,
    nominal: f64,
    (lower, upper): (f64, f64),
) {
    use ParameterVerdict::{Fail, Pass};
    for (measured, expected) in [
        (nominal + upper - 0.01, Pass),
        (nominal + upper + 0.01, Fail),
        (nominal + lower + 0.01, Pass),
        (nominal + lower - 0.01, Fail),
    ] {
        assert_eq!(
            verdict(class, parameter, nominal, measured),
            expected,
            "class {class} {parameter:?}: nominal {nominal}, measured {measured}"
        );
    }
}

#[test]
fn class_verdicts_change_at_the_limits_worked_out_by_hand() {
    // Pitch, in percent of the nominal: a section of pitch 2000 mm, S +-1 % = +-20 mm; III +-5 % = +-100 mm.
    assert_limits(Iso484Class::S, Parameter::Pitch, 2000.0, (-20.0, 20.0));
    assert_limits(Iso484Class::III, Parameter::Pitch, 2000.0, (-100.0, 100.0));
    // A blade's mean pitch, I +-1 %; the propeller's, II +-1 %.
    assert_limits(Iso484Class::I, Parameter::BladePitch, 1500.0, (-15.0, 15.0));
    assert_limits(
        Iso484Class::II,
        Parameter::PropellerPitch,
        1500.0,
        (-15.0, 15.0),
    );
    // Thickness, +2 % / -1 % with a minimum of 2 / 1 mm in S: at 30 mm the minimums hold (0.6 and 0.3 mm are
    // less), at 150 mm the percentages (3 and 1.5 mm are more).
    assert_limits(Iso484Class::S, Parameter::MaxThickness, 30.0, (-1.0, 2.0));
    assert_limits(Iso484Class::S, Parameter::MaxThickness, 150.0, (-1.5, 3.0));
    // III: +6 % / -4 % with a minimum of 6 / 4 mm; at 200 mm, +12 / -8 mm.
    assert_limits(
        Iso484Class::III,
        Parameter::MaxThickness,
        200.0,
        (-8.0, 12.0),
    );
    // Section length, II +-3 % with a minimum of 13 mm: a 100 mm chord gets +-13 mm, a 500 mm chord +-15 mm.
    assert_limits(Iso484Class::II, Parameter::Chord, 100.0, (-13.0, 13.0));
    assert_limits(Iso484Class::II, Parameter::Chord, 500.0, (-15.0, 15.0));
    // Angular spacing: +-1 deg in I, +-2 deg in II.
    assert_limits(
        Iso484Class::I,
        Parameter::AngularSpacing,
        120.0,
        (-1.0, 1.0),
    );
    assert_limits(
        Iso484Class::II,
        Parameter::AngularSpacing,
        120.0,
        (-2.0, 2.0),
    );
}

#[test]
fn the_class_table_reads_and_every_class_is_looser_than_the_one_before() {
    let table = class_table();
    assert!(table.cites.contains("ISO 484-2"));
    for class in CLASSES {
        table.rules(class).check().unwrap();
    }
    for pair in CLASSES.windows(2) {
        let (finer, coarser) = (table.rules(pair[0]), table.rules(pair[1]));
        for ((parameter, name, fine), (_, _, coarse)) in
            finer.entries().into_iter().zip(coarser.entries())
        {
            assert_eq!(
                fine.is_some(),
                coarse.is_some(),
                "{name} in {} and {}",
                pair[0],
                pair[1]
            );
            let (Some(fine), Some(coarse)) = (fine, coarse) else {
                continue;
            };
            for nominal in [1.0, 30.0, 120.0, 2000.0] {
                let (fine_low, fine_high) = fine.limits(nominal);
                let (coarse_low, coarse_high) = coarse.limits(nominal);
                assert!(
                    coarse_low <= fine_low && fine_high <= coarse_high,
                    "{parameter:?} at {nominal}: class {} allows {fine_low}..{fine_high}, class {} {coarse_low}..{coarse_high}",
                    pair[0],
                    pair[1]
                );
            }
        }
    }
    // The parameters the class table has no word on stay unjudged.
    let s = ParameterTolerances::new(Some(Iso484Class::S), ParameterRules::default());
    let mut camber = ParameterValue::of(2.0, 2.5);
    s.judge(Parameter::MaxCamber, &mut camber);
    assert_eq!((camber.tolerance, camber.verdict), (None, None));
}

fn section(chord: (f64, f64), thickness: (f64, f64)) -> SectionParametersReport {
    let value = |(nominal, measured): (f64, f64)| ParameterValue::of(nominal, measured);
    SectionParametersReport {
        edge_distance_mm: 2.0,
        chord_mm: value(chord),
        max_thickness_mm: value(thickness),
        max_thickness_at: value((0.3, 0.3)),
        le_thickness_mm: value((5.0, 5.0)),
        te_thickness_mm: value((1.0, 1.0)),
        le_radius_mm: None,
        te_radius_mm: None,
        max_camber_mm: value((2.0, 2.0)),
        max_camber_at: value((0.4, 0.4)),
        chord_angle_deg: value((40.0, 40.0)),
        chord_middle_mm: None,
        pitch_mm: Some(value((500.0, 500.0))),
        verdict: None,
    }
}

#[test]
fn the_part_files_tolerances_override_the_class_parameter_by_parameter() {
    let part = ParameterRules {
        chord_mm: Some(ToleranceRule {
            lower: Some(-0.05),
            upper: Some(0.05),
            ..ToleranceRule::default()
        }),
        ..ParameterRules::default()
    };
    let tolerances = ParameterTolerances::new(Some(Iso484Class::S), part);
    // A chord 0.06 mm long fails the part file's 0.05 mm, which S (+-7 mm) would pass; the thickness is S's.
    let mut long = section((100.0, 100.06), (20.0, 20.5));
    tolerances.judge_section(&mut long);
    assert_eq!(long.chord_mm.verdict, Some(ParameterVerdict::Fail));
    assert_eq!(
        long.chord_mm.tolerance.unwrap().from,
        ToleranceSource::PartFile
    );
    assert_eq!(long.max_thickness_mm.verdict, Some(ParameterVerdict::Pass));
    assert_eq!(
        long.max_thickness_mm.tolerance.unwrap(),
        AppliedTolerance {
            lower: -1.0,
            upper: 2.0,
            from: ToleranceSource::Iso484(Iso484Class::S)
        }
    );
    assert_eq!(long.verdict, Some(ParameterVerdict::Fail));
    assert_eq!(
        long.out_of_tolerance()
            .into_iter()
            .map(|(name, v)| (name, v.deviation))
            .collect::<Vec<_>>(),
        vec![("chord_mm", long.chord_mm.deviation)]
    );
    let mut good = section((100.0, 100.04), (20.0, 20.5));
    tolerances.judge_section(&mut good);
    assert_eq!(good.verdict, Some(ParameterVerdict::Pass));
    // With neither a class nor a rule, nothing is judged.
    let mut unjudged = section((100.0, 100.06), (20.0, 20.5));
    ParameterTolerances::new(None, ParameterRules::default()).judge_section(&mut unjudged);
    assert_eq!(unjudged.verdict, None);
    assert!(unjudged.judged().all(|(_, v)| v.verdict.is_none()));
}

#[test]
fn a_rule_needs_both_sides_each_on_its_side_of_zero() {
    let rule = |text: &str| toml::from_str::<ToleranceRule>(text).unwrap();
    let problem = rule("upper = 0.1").check("chord_mm").unwrap_err();
    assert!(problem.contains("chord_mm has no lower limit"), "{problem}");
    let problem = rule("lower = 0.1\nupper = 0.2")
        .check("chord_mm")
        .unwrap_err();
    assert!(problem.contains("at most 0"), "{problem}");
    let problem = rule("lower_pct = -1\nupper_pct = -0.5")
        .check("pitch_mm")
        .unwrap_err();
    assert!(problem.contains("pitch_mm: upper limit -0.5"), "{problem}");
    rule("lower_pct = -1\nupper = 0").check("pitch_mm").unwrap();
    assert!(toml::from_str::<ToleranceRule>("plus = 1").is_err());
    // The percent applies to the nominal's size, whatever its sign (a left-handed propeller's pitch).
    assert_eq!(
        rule("lower_pct = -1\nupper_pct = 2").limits(-200.0),
        (-2.0, 4.0)
    );
}
