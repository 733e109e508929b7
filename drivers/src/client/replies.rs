//! Reading the data lines (`#`) of replies into the station's values. A reply of the wrong shape is
//! described in a `String` that becomes `TransportError::BadReply`.

use crate::machine::{MeasuredPoint, ScanPoint, Xyz};
use crate::wire::{Arg, Call, Data};

use super::calls::SCAN_POINT_VALUES;

/// A 0/1 flag property such as `IsHomed(1)` or `ErrStatus(0)`.
pub(crate) fn flag(data: &[Data], name: &str) -> Result<bool, String> {
    match numbers_of(find(data, &[name])?)?[..] {
        [0.0] => Ok(false),
        [1.0] => Ok(true),
        _ => Err(format!("{name} is not 0 or 1")),
    }
}

/// The value of a one-number property under any of `names` (servers differ in the prefix they echo).
pub(crate) fn number(data: &[Data], names: &[&str]) -> Result<f64, String> {
    match numbers_of(find(data, names)?)?[..] {
        [value] => Ok(value),
        _ => Err(format!("{} does not hold one number", names[0])),
    }
}

/// `X(..), Y(..), Z(..), IJK(..)` in any order (NIST's server sends `IJK` first).
pub(crate) fn measured_point(data: &[Data]) -> Result<MeasuredPoint, String> {
    Ok(MeasuredPoint {
        centre: position(data)?,
        normal: triple(numbers_of(find(data, &["IJK"])?)?, "IJK")?,
    })
}

/// `X(..), Y(..), Z(..)`, as a move report or a measurement carries it.
pub(crate) fn position(data: &[Data]) -> Result<Xyz, String> {
    let mut axes = [0.0; 3];
    for (value, axis) in axes.iter_mut().zip(["X", "Y", "Z"]) {
        *value = number(data, &[axis])?;
    }
    Ok(Xyz::new(axes[0], axes[1], axes[2]))
}

/// One data line of a scan: the numbers of one or more points, [`SCAN_POINT_VALUES`] each.
pub(crate) fn scan_points(data: &Data) -> Result<Vec<ScanPoint>, String> {
    let Data::Numbers(numbers) = data else {
        return Err(format!("scan data `{data}` is not a list of numbers"));
    };
    if numbers.len() % SCAN_POINT_VALUES != 0 {
        return Err(format!(
            "scan data has {} numbers, not a multiple of the {SCAN_POINT_VALUES} asked for \
             (X, Y, Z, I, J, K, Q)",
            numbers.len()
        ));
    }
    Ok(numbers
        .chunks_exact(SCAN_POINT_VALUES)
        .map(|point| {
            let value = |index: usize| point[index].value();
            ScanPoint {
                centre: Xyz::new(value(0), value(1), value(2)),
                normal: Xyz::new(value(3), value(4), value(5)),
                quality: value(6),
            }
        })
        .collect())
}

/// The first call named one of `names` in any data line.
fn find<'a>(data: &'a [Data], names: &[&str]) -> Result<&'a Call, String> {
    data.iter()
        .filter_map(|line| match line {
            Data::Calls(calls) => Some(calls),
            _ => None,
        })
        .flatten()
        .find(|call| names.contains(&call.name.as_str()))
        .ok_or_else(|| format!("no {} in the reply", names[0]))
}

fn numbers_of(call: &Call) -> Result<Vec<f64>, String> {
    call.args
        .iter()
        .map(|arg| match arg {
            Arg::Number(number) => Ok(number.value()),
            other => Err(format!("{} holds `{other}`, not a number", call.name)),
        })
        .collect()
}

fn triple(values: Vec<f64>, name: &str) -> Result<Xyz, String> {
    match values[..] {
        [x, y, z] => Ok(Xyz::new(x, y, z)),
        _ => Err(format!("{name} does not hold three numbers")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::wire::{Response, ResponseKind};

    /// The data of a response line, e.g. one copied from NIST's server logs.
    fn data(line: &str) -> Data {
        match line.parse::<Response>().unwrap().into_kind() {
            ResponseKind::Data(data) => data,
            other => panic!("not data: {other:?}"),
        }
    }

    #[test]
    fn reads_nists_pt_meas_reply_in_its_order() {
        // PtMeas_Client.log, tag 00080.
        let reply =
            data("00080 # IJK(0.00000,0.00000,1.00000), X(3.06205), Y(-24.26795), Z(32.73005)");
        let point = measured_point(&[reply]).unwrap();
        assert_eq!(point.centre, Xyz::new(3.06205, -24.26795, 32.73005));
        assert_eq!(point.normal, Xyz::new(0.0, 0.0, 1.0));
    }

    #[test]
    fn reads_flags_and_properties() {
        assert!(flag(&[data("01201 # IsHomed(1)")], "IsHomed").unwrap());
        assert!(!flag(&[data("E0010 # ErrStatus(0)")], "ErrStatus").unwrap());
        assert!(flag(&[data("01201 # IsHomed(2)")], "IsHomed").is_err());
        assert!(flag(&[data("01201 # Homed(1)")], "IsHomed").is_err());
        let radius = data("00030 # Tool.AvrRadius(1.5)");
        assert_eq!(
            number(&[radius], &["Tool.AvrRadius", "AvrRadius"]).unwrap(),
            1.5
        );
        let text = data("00030 # Tool.AvrRadius(\"big\")");
        assert!(number(&[text], &["Tool.AvrRadius"]).is_err());
    }

    #[test]
    fn splits_blocked_scan_lines_into_points() {
        // Two points in one line, as the spec's 11.2.8 example blocks them.
        let line = data("00017 # 10.0,0.0,1.5,0.001,0.002,0.999,0.01,12.02,0.0,1.501,0,0,1,0");
        let points = scan_points(&line).unwrap();
        assert_eq!(points.len(), 2);
        assert_eq!(points[0].centre, Xyz::new(10.0, 0.0, 1.5));
        assert_eq!(points[0].normal, Xyz::new(0.001, 0.002, 0.999));
        assert_eq!(points[0].quality, 0.01);
        assert_eq!(points[1].centre, Xyz::new(12.02, 0.0, 1.501));
        // NIST's ScanInPlaneEndIsSphere reply in the default format (X, Y, Z, Q) is not ours.
        let nist = data("00010 # 0.00000,0.49111,0.00000,3.00000,0.00000,0.99222,0.00000,3.00000");
        assert!(scan_points(&nist)
            .unwrap_err()
            .contains("multiple of the 7"));
        assert!(scan_points(&data("00010 # X(1)")).is_err());
    }
}
