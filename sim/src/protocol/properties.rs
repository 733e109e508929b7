//! The active tool's parameter blocks (spec 6.3.6 GoToPar, 6.3.7 PtMeasPar, 6.3.15 ScanPar) for GetProp and
//! SetProp: each value has Min, Max, Def and Act; a bare name means Act; only Act can be set, clamped into
//! [Min, Max] with warning 0504 when it had to be.

use crate::config::{Params, Range3};

use super::errors::code;

/// One parameter.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Param {
    pub min: f64,
    pub max: f64,
    pub def: f64,
    pub act: f64,
}

impl Param {
    fn new([min, def, max]: Range3) -> Self {
        Param {
            min,
            max,
            def,
            act: def,
        }
    }
}

/// The parameter blocks of the active tool.
#[derive(Debug, Clone, PartialEq)]
pub struct Properties {
    pub goto_speed: Param,
    pub goto_accel: Param,
    pub ptmeas_speed: Param,
    pub ptmeas_accel: Param,
    pub ptmeas_approach: Param,
    pub ptmeas_search: Param,
    pub ptmeas_retract: Param,
    pub scan_speed: Param,
    pub scan_accel: Param,
}

/// What a property name refers to.
enum Field {
    Act,
    Min,
    Max,
    Def,
}

impl Properties {
    /// All parameters at their defaults, as after a tool change (spec 6.3.6).
    pub fn new(params: &Params) -> Self {
        Properties {
            goto_speed: Param::new(params.goto_speed),
            goto_accel: Param::new(params.goto_accel),
            ptmeas_speed: Param::new(params.ptmeas_speed),
            ptmeas_accel: Param::new(params.ptmeas_accel),
            ptmeas_approach: Param::new(params.ptmeas_approach),
            ptmeas_search: Param::new(params.ptmeas_search),
            ptmeas_retract: Param::new(params.ptmeas_retract),
            scan_speed: Param::new(params.scan_speed),
            scan_accel: Param::new(params.scan_accel),
        }
    }

    /// The parameter and field a name such as `Tool.PtMeasPar.Speed.Max` refers to.
    fn find(&mut self, name: &str) -> Option<(&mut Param, Field)> {
        let (base, field) = match name.rsplit_once('.') {
            Some((base, "Act")) => (base, Field::Act),
            Some((base, "Min")) => (base, Field::Min),
            Some((base, "Max")) => (base, Field::Max),
            Some((base, "Def")) => (base, Field::Def),
            _ => (name, Field::Act),
        };
        let param = match base {
            "Tool.GoToPar.Speed" => &mut self.goto_speed,
            "Tool.GoToPar.Accel" => &mut self.goto_accel,
            "Tool.PtMeasPar.Speed" => &mut self.ptmeas_speed,
            "Tool.PtMeasPar.Accel" => &mut self.ptmeas_accel,
            "Tool.PtMeasPar.Approach" => &mut self.ptmeas_approach,
            "Tool.PtMeasPar.Search" => &mut self.ptmeas_search,
            "Tool.PtMeasPar.Retract" => &mut self.ptmeas_retract,
            "Tool.ScanPar.Speed" => &mut self.scan_speed,
            "Tool.ScanPar.Accel" => &mut self.scan_accel,
            _ => return None,
        };
        Some((param, field))
    }

    /// The value of a parameter name, or 0510.
    pub fn get(&mut self, name: &str) -> Result<f64, u16> {
        let (param, field) = self.find(name).ok_or(code::BAD_PROPERTY)?;
        Ok(match field {
            Field::Act => param.act,
            Field::Min => param.min,
            Field::Max => param.max,
            Field::Def => param.def,
        })
    }

    /// Sets an Act value; `Ok(true)` when it had to be clamped (warning 0504). Min, Max and Def cannot be
    /// set (0510).
    pub fn set(&mut self, name: &str, value: f64) -> Result<bool, u16> {
        match self.find(name) {
            Some((param, Field::Act)) => {
                param.act = value.clamp(param.min, param.max);
                Ok(param.act != value)
            }
            _ => Err(code::BAD_PROPERTY),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bare_names_mean_act_and_only_act_is_set_within_range() {
        let mut props = Properties::new(&Params::default());
        assert_eq!(props.get("Tool.GoToPar.Speed"), Ok(100.0));
        assert_eq!(props.set("Tool.GoToPar.Speed.Act", 50.0), Ok(false));
        assert_eq!(props.get("Tool.GoToPar.Speed"), Ok(50.0));
        assert_eq!(props.set("Tool.GoToPar.Speed", 9999.0), Ok(true));
        assert_eq!(props.get("Tool.GoToPar.Speed.Act"), Ok(500.0));
        assert_eq!(props.get("Tool.GoToPar.Speed.Def"), Ok(100.0));
        assert_eq!(
            props.set("Tool.GoToPar.Speed.Max", 1.0),
            Err(code::BAD_PROPERTY)
        );
        assert_eq!(props.get("Tool.Colour"), Err(code::BAD_PROPERTY));
    }
}
