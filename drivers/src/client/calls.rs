//! The I++ calls (command lines without their tags) for the station's operations.

use crate::codec::MAX_LINE_LEN;
use crate::machine::{
    CurveScan, Density, InPlaneScan, InPlaneSpacing, MoveReportRate, Speeds, Xyz,
};
use crate::wire::{Arg, Call, EventTag, Keyword, Name, Number, WireError, WireString};

/// The values of one scan point in the format [`on_scan_report`] asks for.
pub(crate) const SCAN_POINT_VALUES: usize = 7;

/// A call without arguments, such as `Home()`.
pub(crate) fn bare(name: &'static str) -> Call {
    Call::new(known_name(name), Vec::new())
}

pub(crate) fn go_to(target: Xyz) -> Result<Call, WireError> {
    Ok(Call::new(known_name("GoTo"), axes(target)?))
}

/// `PtMeas(X(..), Y(..), Z(..), IJK(..))`.
pub(crate) fn pt_meas(nominal: Xyz, normal: Xyz) -> Result<Call, WireError> {
    let mut args = axes(nominal)?;
    args.push(property("IJK", numbers(&xyz(normal))?));
    Ok(Call::new(known_name("PtMeas"), args))
}

/// Asks `PtMeas` to report the ball centre and the normal; the spec's default is the centre only.
pub(crate) fn on_pt_meas_report() -> Call {
    report_format("OnPtMeasReport", &["X", "Y", "Z", "IJK"])
}

/// Asks scans for [`SCAN_POINT_VALUES`] numbers per point: the ball centre, the normal, the quality.
pub(crate) fn on_scan_report() -> Call {
    report_format("OnScanReport", &["X", "Y", "Z", "IJK", "Q"])
}

pub(crate) fn change_tool(name: &str) -> Result<Call, WireError> {
    let name = WireString::new(name)?;
    Ok(Call::new(known_name("ChangeTool"), vec![name.into()]))
}

/// `Get(X(), Y(), Z())`: the probe centre's position (spec 6.3.2.6).
pub(crate) fn get_position() -> Call {
    report_format("Get", &["X", "Y", "Z"])
}

/// `GetProp(Tool.AvrRadius())`: spec 6.3.13's calibrated tip radius of the active tool.
pub(crate) fn get_tool_radius() -> Call {
    Call::new(
        known_name("GetProp"),
        vec![property("Tool.AvrRadius", Vec::new())],
    )
}

pub(crate) fn set_speeds(speeds: Speeds) -> Result<Call, WireError> {
    let args = vec![
        property("Tool.GoToPar.Speed", numbers(&[speeds.travel])?),
        property("Tool.PtMeasPar.Speed", numbers(&[speeds.probing])?),
        property("Tool.ScanPar.Speed", numbers(&[speeds.scanning])?),
    ];
    Ok(Call::new(known_name("SetProp"), args))
}

/// `ScanInPlaneEndIsSphere(Sx,Sy,Sz,Si,Sj,Sk,Ni,Nj,Nk,Dx,Dy,Dz,StepW,Ex,Ey,Ez,Dia,n,Ei,Ej,Ek)`.
pub(crate) fn scan_in_plane(plan: &InPlaneScan) -> Result<Call, WireError> {
    let mut values = Vec::with_capacity(21);
    for point in [
        plan.start,
        plan.start_normal,
        plan.plane_normal,
        plan.direction,
    ] {
        values.extend(xyz(point));
    }
    // Spec 11.3.1.1: StepW 0 asks the machine for ScanUnknownDensity's spacing.
    values.push(match plan.spacing {
        InPlaneSpacing::Step(step) => step,
        InPlaneSpacing::Spacing { .. } => 0.0,
    });
    values.extend(xyz(plan.end));
    values.push(plan.stop_diameter);
    values.push(f64::from(plan.passes));
    values.extend(xyz(plan.end_normal));
    Ok(Call::new(
        known_name("ScanInPlaneEndIsSphere"),
        numbers(&values)?,
    ))
}

/// `ScanUnknownDensity(Dis(..), Angle(..))`, the angle in degrees (as `ScanOnCurveDensity`'s), for an
/// in-plane scan spaced by distance and turn; none for one spaced by `StepW`.
pub(crate) fn scan_unknown_density(plan: &InPlaneScan) -> Option<Result<Call, WireError>> {
    let InPlaneSpacing::Spacing {
        max_distance,
        max_angle,
    } = plan.spacing
    else {
        return None;
    };
    let args = || {
        Ok(vec![
            property("Dis", numbers(&[max_distance])?),
            property("Angle", numbers(&[max_angle.to_degrees()])?),
        ])
    };
    Some(args().map(|args| Call::new(known_name("ScanUnknownDensity"), args)))
}

/// `ScanOnCurveHint(Deviation, MinRadiusOfCurvature)`.
pub(crate) fn scan_on_curve_hint(plan: &CurveScan) -> Result<Call, WireError> {
    Ok(Call::new(
        known_name("ScanOnCurveHint"),
        numbers(&[plan.max_deviation, plan.min_radius])?,
    ))
}

/// `ScanOnCurveDensity(Dis(..), Angle(..), AtNominals(..))`; the angle in degrees, as the spec's
/// example `Angle(10)` shows. With `AtNominals(1)` the spec ignores the others, so they are left out.
pub(crate) fn scan_on_curve_density(density: Density) -> Result<Call, WireError> {
    let args = match density {
        Density::AtNominals => vec![property("AtNominals", numbers(&[1.0])?)],
        Density::Spacing {
            max_distance,
            max_angle,
        } => vec![
            property("Dis", numbers(&[max_distance])?),
            property("Angle", numbers(&[max_angle.to_degrees()])?),
            property("AtNominals", numbers(&[0.0])?),
        ],
    };
    Ok(Call::new(known_name("ScanOnCurveDensity"), args))
}

/// `ScanOnCurve(Closed(..), Format(X(), Y(), Z(), IJK(), tag), Data(..))`, every nominal tagged +1 (on
/// the surface). Refused when the line would pass the spec's length limit.
pub(crate) fn scan_on_curve(plan: &CurveScan) -> Result<Call, WireError> {
    let format = ["X", "Y", "Z", "IJK"]
        .into_iter()
        .map(|name| property(name, Vec::new()))
        .chain([Keyword::new("tag")?.into()])
        .collect();
    let mut data = Vec::with_capacity(plan.nominals.len() * SCAN_POINT_VALUES);
    for nominal in &plan.nominals {
        data.extend(xyz(nominal.point));
        data.extend(xyz(nominal.normal));
        data.push(1.0);
    }
    let closed = if plan.closed { 1.0 } else { 0.0 };
    let call = Call::new(
        known_name("ScanOnCurve"),
        vec![
            property("Closed", numbers(&[closed])?),
            property("Format", format),
            property("Data", numbers(&data)?),
        ],
    );
    // The tag and its space come before the call on the line.
    let len = "00001 ".len() + call.to_string().len();
    if len > MAX_LINE_LEN {
        return Err(WireError::LineTooLong {
            len,
            max: MAX_LINE_LEN,
        });
    }
    Ok(call)
}

/// `OnMoveReportE(Time(..), Dis(..), X(), Y(), Z())`.
pub(crate) fn on_move_report(rate: MoveReportRate) -> Result<Call, WireError> {
    let mut args = vec![
        property("Time", numbers(&[rate.interval.as_secs_f64()])?),
        property("Dis", numbers(&[rate.distance])?),
    ];
    args.extend(["X", "Y", "Z"].map(|axis| property(axis, Vec::new())));
    Ok(Call::new(known_name("OnMoveReportE"), args))
}

pub(crate) fn stop_daemon(daemon: EventTag) -> Call {
    Call::new(known_name("StopDaemon"), vec![daemon.into()])
}

/// A name written in this file, so known to be valid.
fn known_name(text: &'static str) -> Name {
    Name::new(text).expect("names in calls.rs are valid")
}

fn property(name: &'static str, args: Vec<Arg>) -> Arg {
    Call::new(known_name(name), args).into()
}

fn report_format(command: &'static str, items: &[&'static str]) -> Call {
    let args = items
        .iter()
        .map(|item| property(item, Vec::new()))
        .collect();
    Call::new(known_name(command), args)
}

/// `X(..), Y(..), Z(..)`.
fn axes(point: Xyz) -> Result<Vec<Arg>, WireError> {
    ["X", "Y", "Z"]
        .into_iter()
        .zip(xyz(point))
        .map(|(axis, value)| Ok(property(axis, numbers(&[value])?)))
        .collect()
}

fn xyz(point: Xyz) -> [f64; 3] {
    [point.x, point.y, point.z]
}

fn numbers(values: &[f64]) -> Result<Vec<Arg>, WireError> {
    values
        .iter()
        .map(|&value| Number::from_f64(value).map(Arg::from))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::machine::Nominal;
    use std::time::Duration;

    #[test]
    fn writes_the_spec_forms() {
        let goto = go_to(Xyz::new(100.0, -0.5, 12.25)).unwrap();
        assert_eq!(goto.to_string(), "GoTo(X(100), Y(-0.5), Z(12.25))");
        let ptmeas = pt_meas(Xyz::new(1.0, 2.0, 3.0), Xyz::new(0.0, 0.0, 1.0)).unwrap();
        assert_eq!(ptmeas.to_string(), "PtMeas(X(1), Y(2), Z(3), IJK(0, 0, 1))");
        assert_eq!(
            on_scan_report().to_string(),
            "OnScanReport(X(), Y(), Z(), IJK(), Q())"
        );
        assert_eq!(get_tool_radius().to_string(), "GetProp(Tool.AvrRadius())");
        let rate = MoveReportRate {
            interval: Duration::from_millis(500),
            distance: 0.2,
        };
        assert_eq!(
            on_move_report(rate).unwrap().to_string(),
            "OnMoveReportE(Time(0.5), Dis(0.2), X(), Y(), Z())"
        );
        let speeds = Speeds {
            travel: 50.0,
            probing: 5.0,
            scanning: 10.0,
        };
        assert_eq!(
            set_speeds(speeds).unwrap().to_string(),
            "SetProp(Tool.GoToPar.Speed(50), Tool.PtMeasPar.Speed(5), Tool.ScanPar.Speed(10))"
        );
    }

    #[test]
    fn writes_a_scan_in_plane_like_nists_log() {
        // ScanInPlaneEndIsSphere_Client.log sends the spec's 21 arguments in this order.
        let plan = InPlaneScan {
            start: Xyz::new(0.0, 0.0, 0.0),
            start_normal: Xyz::new(0.0, 0.0, 1.0),
            plane_normal: Xyz::new(1.0, 0.0, 0.0),
            direction: Xyz::new(0.0, 1.0, 0.0),
            spacing: InPlaneSpacing::Step(0.5),
            end: Xyz::new(0.0, 9.0, 0.0),
            stop_diameter: 1.4,
            passes: 1,
            end_normal: Xyz::new(0.0, 0.0, 1.0),
        };
        assert_eq!(
            scan_in_plane(&plan).unwrap().to_string(),
            "ScanInPlaneEndIsSphere(0, 0, 0, 0, 0, 1, 1, 0, 0, 0, 1, 0, 0.5, 0, 9, 0, 1.4, 1, 0, 0, 1)"
        );
        assert!(scan_unknown_density(&plan).is_none());
        // Spaced by distance and turn: the density first, then the scan with StepW 0.
        let spaced = InPlaneScan {
            spacing: InPlaneSpacing::Spacing {
                max_distance: 1.0,
                max_angle: 10f64.to_radians(),
            },
            ..plan
        };
        assert_eq!(
            scan_unknown_density(&spaced).unwrap().unwrap().to_string(),
            "ScanUnknownDensity(Dis(1), Angle(10))"
        );
        assert_eq!(
            scan_in_plane(&spaced).unwrap().to_string(),
            "ScanInPlaneEndIsSphere(0, 0, 0, 0, 0, 1, 1, 0, 0, 0, 1, 0, 0, 0, 9, 0, 1.4, 1, 0, 0, 1)"
        );
    }

    fn curve(nominals: usize) -> CurveScan {
        let nominal = Nominal {
            point: Xyz::new(10.0, 0.0, 0.0),
            normal: Xyz::new(0.0, 0.0, 1.0),
        };
        CurveScan {
            closed: false,
            nominals: vec![nominal; nominals],
            max_deviation: 0.01,
            min_radius: 0.5,
            density: Density::Spacing {
                max_distance: 1.0,
                max_angle: 10f64.to_radians(),
            },
        }
    }

    #[test]
    fn writes_the_spec_curve_scan_example() {
        let plan = curve(2);
        assert_eq!(
            scan_on_curve_hint(&plan).unwrap().to_string(),
            "ScanOnCurveHint(0.01, 0.5)"
        );
        assert_eq!(
            scan_on_curve_density(plan.density).unwrap().to_string(),
            "ScanOnCurveDensity(Dis(1), Angle(10), AtNominals(0))"
        );
        assert_eq!(
            scan_on_curve_density(Density::AtNominals)
                .unwrap()
                .to_string(),
            "ScanOnCurveDensity(AtNominals(1))"
        );
        assert_eq!(
            scan_on_curve(&plan).unwrap().to_string(),
            "ScanOnCurve(Closed(0), Format(X(), Y(), Z(), IJK(), tag), \
             Data(10, 0, 0, 0, 0, 1, 1, 10, 0, 0, 0, 0, 1, 1))"
        );
    }

    #[test]
    fn refuses_what_cannot_go_on_the_wire() {
        assert_eq!(
            go_to(Xyz::new(f64::NAN, 0.0, 0.0)),
            Err(WireError::NonFiniteNumber)
        );
        assert!(matches!(
            change_tool("say \"hi\""),
            Err(WireError::InvalidString(_))
        ));
        assert!(matches!(
            scan_on_curve(&curve(3_000)),
            Err(WireError::LineTooLong { .. })
        ));
    }
}
