//! Reading command arguments and writing data responses: numbers, property calls like `X(100)`, and the
//! report formats of OnPtMeasReport/OnScanReport/OnMoveReportE.

use nalgebra::{Point3, Vector3};
use zeroset_drivers::wire::{Arg, Call, Data, Name, Number, Response, ResponseKind, Tag};

use super::errors::code;

/// A plain number argument.
pub fn number(arg: &Arg) -> Option<f64> {
    match arg {
        Arg::Number(n) => Some(n.value()),
        _ => None,
    }
}

/// All arguments as numbers, or the error code for arguments that are not.
pub fn numbers(args: &[Arg]) -> Result<Vec<f64>, u16> {
    args.iter()
        .map(|a| number(a).ok_or(code::INCORRECT_ARGUMENTS))
        .collect()
}

/// A call argument such as `X(100)`: its name and arguments.
pub fn call(arg: &Arg) -> Option<&Call> {
    match arg {
        Arg::Call(call) => Some(call),
        _ => None,
    }
}

/// The single number inside a call such as `Dis(1.5)`.
pub fn call_number(call: &Call) -> Result<f64, u16> {
    match call.args.as_slice() {
        [arg] => number(arg).ok_or(code::BAD_ARGUMENT),
        _ => Err(code::INCORRECT_ARGUMENTS),
    }
}

/// A unit vector, or 1010 for a zero one.
pub fn unit(v: Vector3<f64>) -> Result<Vector3<f64>, u16> {
    let norm = v.norm();
    if norm > 1e-12 && norm.is_finite() {
        Ok(v / norm)
    } else {
        Err(code::VECTOR_HAS_NO_NORM)
    }
}

/// Rounds to 0.01 um, as a CMM's resolution, so lines stay short.
pub fn wire_number(value: f64) -> Number {
    Number::from_f64((value * 1e5).round() / 1e5).expect("finite machine values")
}

/// `name(values...)`.
pub fn value_call(name: &str, values: &[f64]) -> Call {
    Call::new(
        Name::new(name).expect("the simulator's names are valid"),
        values
            .iter()
            .map(|v| Arg::Number(wire_number(*v)))
            .collect(),
    )
}

/// A data line of calls.
pub fn data_calls(tag: Tag, calls: Vec<Call>) -> Response {
    Response::new(tag, ResponseKind::Data(Data::Calls(calls))).expect("non-empty data")
}

/// A data line of numbers.
pub fn data_numbers(tag: Tag, values: &[f64]) -> Response {
    let numbers = values.iter().map(|v| wire_number(*v)).collect();
    Response::new(tag, ResponseKind::Data(Data::Numbers(numbers))).expect("non-empty data")
}

/// One item of a report format.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Item {
    X,
    Y,
    Z,
    Ijk,
    Q,
    Er,
}

impl Item {
    fn name(self) -> &'static str {
        match self {
            Item::X => "X",
            Item::Y => "Y",
            Item::Z => "Z",
            Item::Ijk => "IJK",
            Item::Q => "Q",
            Item::Er => "ER",
        }
    }
}

/// What a reported point carries.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reading {
    pub centre: Point3<f64>,
    pub normal: Vector3<f64>,
    pub radius: f64,
}

impl Reading {
    fn values(&self, item: Item) -> Vec<f64> {
        match item {
            Item::X => vec![self.centre.x],
            Item::Y => vec![self.centre.y],
            Item::Z => vec![self.centre.z],
            Item::Ijk => self.normal.iter().copied().collect(),
            // A tactile probe on a smooth analytic part: every point is good.
            Item::Q => vec![0.0],
            Item::Er => vec![self.radius],
        }
    }

    /// As calls, for PtMeas and move reports: `X(1), Y(2), IJK(0, 0, 1)`.
    pub fn calls(&self, items: &[Item]) -> Vec<Call> {
        items
            .iter()
            .map(|item| value_call(item.name(), &self.values(*item)))
            .collect()
    }

    /// As bare numbers, for scans (spec 11.1.2: no names in scan data).
    pub fn numbers(&self, items: &[Item], out: &mut Vec<f64>) {
        for item in items {
            out.extend(self.values(*item));
        }
    }
}

/// Reads a report format such as `X(), Y(), Z(), IJK()`; `allowed` limits the items (move reports carry
/// positions only). Anything else is 0510 Bad property.
pub fn report_items(args: &[Arg], allowed: &[Item]) -> Result<Vec<Item>, u16> {
    if args.is_empty() {
        return Err(code::INCORRECT_ARGUMENTS);
    }
    args.iter()
        .map(|arg| {
            let call = call(arg).ok_or(code::BAD_PROPERTY)?;
            let item = allowed
                .iter()
                .copied()
                .find(|item| item.name() == call.name.as_str())
                .ok_or(code::BAD_PROPERTY)?;
            if call.args.is_empty() {
                Ok(item)
            } else {
                Err(code::BAD_ARGUMENT)
            }
        })
        .collect()
}

pub const ALL_ITEMS: [Item; 6] = [Item::X, Item::Y, Item::Z, Item::Ijk, Item::Q, Item::Er];
pub const POSITION_ITEMS: [Item; 3] = [Item::X, Item::Y, Item::Z];

/// The target of GoTo or PtMeas: `X(..)`, `Y(..)`, `Z(..)` in any order, the missing axes from `current`,
/// and an optional `IJK(..)` when `ijk_allowed`.
pub fn target(
    args: &[Arg],
    current: Point3<f64>,
    ijk_allowed: bool,
) -> Result<(Point3<f64>, Option<Vector3<f64>>), u16> {
    if args.is_empty() {
        return Err(code::INCORRECT_ARGUMENTS);
    }
    let mut target = current;
    let mut ijk = None;
    let mut axes = 0;
    for arg in args {
        let call = call(arg).ok_or(code::INCORRECT_ARGUMENTS)?;
        match call.name.as_str() {
            "X" => target.x = call_number(call)?,
            "Y" => target.y = call_number(call)?,
            "Z" => target.z = call_number(call)?,
            "IJK" if ijk_allowed => {
                let v = numbers(&call.args).map_err(|_| code::BAD_ARGUMENT)?;
                let [i, j, k] = v[..] else {
                    return Err(code::INCORRECT_ARGUMENTS);
                };
                ijk = Some(Vector3::new(i, j, k));
                continue;
            }
            "IJK" => return Err(code::BAD_CONTEXT),
            _ => return Err(code::BAD_ARGUMENT),
        }
        axes += 1;
    }
    // Spec 6.3.2.13: "The argument IJK(..) without any linear axis coordinates is currently not allowed."
    if axes == 0 {
        return Err(code::INCORRECT_ARGUMENTS);
    }
    Ok((target, ijk))
}

#[cfg(test)]
mod tests {
    use super::*;
    use zeroset_drivers::wire::Command;

    fn args(line: &str) -> Vec<Arg> {
        line.parse::<Command>().unwrap().args().to_vec()
    }

    #[test]
    fn reads_targets_and_keeps_missing_axes() {
        let here = Point3::new(1.0, 2.0, 3.0);
        let (to, ijk) =
            target(&args("00001 PtMeas(Z(5), X(-1), IJK(0, 0, 2))"), here, true).unwrap();
        assert_eq!(to, Point3::new(-1.0, 2.0, 5.0));
        assert_eq!(ijk, Some(Vector3::new(0.0, 0.0, 2.0)));
        assert_eq!(
            target(&args("00001 GoTo(X(1), IJK(0, 0, 1))"), here, false),
            Err(code::BAD_CONTEXT)
        );
        assert_eq!(
            target(&args("00001 PtMeas(IJK(0, 0, 1))"), here, true),
            Err(code::INCORRECT_ARGUMENTS)
        );
        assert_eq!(
            target(&args("00001 GoTo(Tool.A(3))"), here, false),
            Err(code::BAD_ARGUMENT)
        );
    }

    #[test]
    fn reads_report_formats_and_writes_readings() {
        let items = report_items(
            &args("00001 OnScanReport(X(), Y(), Z(), IJK(), Q())"),
            &ALL_ITEMS,
        )
        .unwrap();
        let reading = Reading {
            centre: Point3::new(1.0, 2.0, 3.123456789),
            normal: Vector3::new(0.0, 0.0, 1.0),
            radius: 1.0,
        };
        let mut out = Vec::new();
        reading.numbers(&items, &mut out);
        assert_eq!(out, [1.0, 2.0, 3.123456789, 0.0, 0.0, 1.0, 0.0]);
        let line = data_calls(
            Tag::Unsolicited,
            reading.calls(&[Item::X, Item::Z, Item::Ijk]),
        );
        assert_eq!(line.to_string(), "E0000 # X(1), Z(3.12346), IJK(0, 0, 1)");
        assert_eq!(
            report_items(&args("00001 OnPtMeasReport(R())"), &ALL_ITEMS),
            Err(code::BAD_PROPERTY)
        );
        assert_eq!(
            report_items(&args("E0001 OnMoveReportE(IJK())"), &POSITION_ITEMS),
            Err(code::BAD_PROPERTY)
        );
    }
}
