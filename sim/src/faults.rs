//! Faults on demand: from the config (`faults = [{ after_commands = N, kind = "...", ... }]`) or from the
//! control channel, a line on the simulator's standard input: `fault MACHINE KIND [ARG]`.
//!
//! | KIND                  | ARG     | effect                                                               |
//! |-----------------------|---------|----------------------------------------------------------------------|
//! | `garbage`             |         | a line of bytes that are not I++ (high bytes, NUL, ESC) at once       |
//! | `drop-lines`          | count   | the next `count` reply lines are lost                                |
//! | `delay`               | ms      | the replies to the next command come `ms` wall-clock ms late          |
//! | `disconnect`          | ms      | the line goes dead for `ms` (TCP: closed); the session is lost        |
//! | `estop`               |         | `E0000 ! Error(3, 0500, ...)`: motion stops, ClearAllErrors needed    |
//! | `collision`           |         | the next move stops halfway with 2504                                |
//! | `no-touch`            |         | the next PtMeas finds no surface, or the next scan loses its touch    |
//! |                       |         | halfway (its first half's points sent, the probe stopped there): 1003 |
//! | `surface-not-found`   |         | the next scan finds no surface: 1006                                  |
//!
//! Delays and dead lines are wall-clock times, not scaled by `time_scale`: they exist to exercise the
//! client's own timeouts, which are wall-clock.

use serde::Deserialize;

/// One fault.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum Fault {
    Garbage,
    DropLines { count: u32 },
    Delay { ms: u64 },
    Disconnect { ms: u64 },
    Estop,
    Collision,
    NoTouch,
    SurfaceNotFound,
}

/// A fault from the config, fired when the machine has received its `after_commands`th command line.
/// (Unknown keys are refused by [`Fault`], which receives every key but `after_commands`.)
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
pub struct ScheduledFault {
    pub after_commands: u64,
    #[serde(flatten)]
    pub fault: Fault,
}

/// A control-channel request: a fault for a named machine.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FaultRequest {
    pub machine: String,
    pub fault: Fault,
}

impl Fault {
    /// Reads `KIND [ARG]`.
    pub fn parse(words: &[&str]) -> Result<Self, String> {
        let number = |what: &str| -> Result<u64, String> {
            match words {
                [_, arg] => arg
                    .parse()
                    .map_err(|_| format!("{what} must be a whole number, not {arg:?}")),
                _ => Err(format!("`{}` takes one argument: {what}", words[0])),
            }
        };
        let bare = |fault: Fault| -> Result<Fault, String> {
            if words.len() == 1 {
                Ok(fault)
            } else {
                Err(format!("`{}` takes no argument", words[0]))
            }
        };
        match words.first().copied() {
            Some("garbage") => bare(Fault::Garbage),
            Some("drop-lines") => Ok(Fault::DropLines {
                count: u32::try_from(number("count")?).map_err(|e| e.to_string())?,
            }),
            Some("delay") => Ok(Fault::Delay { ms: number("ms")? }),
            Some("disconnect") => Ok(Fault::Disconnect { ms: number("ms")? }),
            Some("estop") => bare(Fault::Estop),
            Some("collision") => bare(Fault::Collision),
            Some("no-touch") => bare(Fault::NoTouch),
            Some("surface-not-found") => bare(Fault::SurfaceNotFound),
            Some(other) => Err(format!(
                "unknown fault {other:?}; one of garbage, drop-lines N, delay MS, disconnect MS, \
                 estop, collision, no-touch, surface-not-found"
            )),
            None => Err("a fault kind is missing".into()),
        }
    }
}

impl FaultRequest {
    /// Reads a control line `fault MACHINE KIND [ARG]`.
    pub fn parse(line: &str) -> Result<Self, String> {
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.as_slice() {
            ["fault", machine, rest @ ..] => Ok(FaultRequest {
                machine: (*machine).to_owned(),
                fault: Fault::parse(rest)?,
            }),
            _ => Err(format!(
                "expected `fault MACHINE KIND [ARG]`, got {:?}",
                line.trim()
            )),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_control_lines() {
        assert_eq!(
            FaultRequest::parse("fault cmm1 delay 250\n"),
            Ok(FaultRequest {
                machine: "cmm1".into(),
                fault: Fault::Delay { ms: 250 }
            })
        );
        assert_eq!(
            FaultRequest::parse("fault cmm2 estop").unwrap().fault,
            Fault::Estop
        );
        assert!(FaultRequest::parse("fault cmm1 estop now").is_err());
        assert!(FaultRequest::parse("fault cmm1 drop-lines x").is_err());
        assert!(FaultRequest::parse("fault cmm1 meteor").is_err());
        assert!(FaultRequest::parse("hello").is_err());
    }

    #[test]
    fn reads_scheduled_faults_from_toml() {
        #[derive(Deserialize)]
        struct Holder {
            faults: Vec<ScheduledFault>,
        }
        let holder: Holder = toml::from_str(
            "faults = [{ after_commands = 3, kind = \"drop-lines\", count = 2 }, \
             { after_commands = 9, kind = \"estop\" }]",
        )
        .unwrap();
        assert_eq!(
            holder.faults,
            [
                ScheduledFault {
                    after_commands: 3,
                    fault: Fault::DropLines { count: 2 }
                },
                ScheduledFault {
                    after_commands: 9,
                    fault: Fault::Estop
                }
            ]
        );
    }
}
