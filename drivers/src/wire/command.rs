//! Command lines, client to server (spec 6.2.2.1): `Tag " " Name(args)`.

use std::fmt;
use std::str::FromStr;

use super::cursor::{check_characters, Cursor};
use super::value::{args_nesting, write_list, MAX_NESTING};
use super::{Arg, LineError, Name, Tag, WireError};

/// One command line, e.g. `00002 GoTo(X(100))` or `E0001 AbortE()`.
#[derive(Debug, Clone, PartialEq)]
pub struct Command {
    tag: Tag,
    name: Name,
    args: Vec<Arg>,
}

impl Command {
    /// The command, if it may go on the wire: the tag is not E0000, an event tag goes with a fast-queue
    /// command (spec 6.2.1: their names end in `E`, and "only event commands may be send with an event
    /// tag") and a command tag with any other, and calls nest at most [`MAX_NESTING`] deep.
    pub fn new(tag: Tag, name: Name, args: Vec<Arg>) -> Result<Self, WireError> {
        let fast_queue = name.as_str().ends_with('E');
        match tag {
            Tag::Unsolicited => return Err(WireError::UnsolicitedTagInCommand),
            Tag::Command(_) if fast_queue => {
                return Err(WireError::FastCommandWithoutEventTag {
                    name: name.as_str().to_owned(),
                })
            }
            Tag::Event(_) if !fast_queue => {
                return Err(WireError::EventTagOnNormalCommand {
                    name: name.as_str().to_owned(),
                })
            }
            Tag::Command(_) | Tag::Event(_) => {}
        }
        if 1 + args_nesting(&args) > MAX_NESTING {
            return Err(WireError::NestingTooDeep { max: MAX_NESTING });
        }
        Ok(Command { tag, name, args })
    }

    /// Reads one line, without its CR LF.
    pub fn parse(line: &[u8]) -> Result<Self, LineError> {
        check_characters(line)?;
        let tag = Tag::parse(line).map_err(|problem| LineError::new(problem, line, 1))?;
        if line.get(5) != Some(&b' ') {
            return Err(LineError::new(WireError::MissingSpaceAfterTag, line, 6));
        }
        let mut cursor = Cursor::new(line, 6);
        let name = cursor.name("a command name")?;
        let args = cursor.call_args(1)?;
        cursor.expect_end()?;
        Command::new(tag, name, args).map_err(|problem| LineError::new(problem, line, 1))
    }

    /// The tag the responses will carry.
    pub fn tag(&self) -> Tag {
        self.tag
    }

    /// The method, e.g. `GoTo`.
    pub fn name(&self) -> &Name {
        &self.name
    }

    /// The arguments inside the parentheses.
    pub fn args(&self) -> &[Arg] {
        &self.args
    }
}

impl FromStr for Command {
    type Err = LineError;

    fn from_str(line: &str) -> Result<Self, LineError> {
        Command::parse(line.as_bytes())
    }
}

impl fmt::Display for Command {
    /// The line without its CR LF.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} {}(", self.tag, self.name)?;
        write_list(f, &self.args)?;
        f.write_str(")")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn problem(line: &str) -> (WireError, usize) {
        let error = line.parse::<Command>().unwrap_err();
        (error.problem().clone(), error.column())
    }

    #[test]
    fn reads_the_spec_examples() {
        for line in [
            "00001 Home()",
            "00002 GoTo(X(100))",
            "00005 Get(X(), Y())",
            "E0553 OnMoveReportE(Time(1),Dis(20),X(), Y(), Z())",
            "00049 StopDaemon(E0553)",
            "00016 ScanOnCurveDensity (Dis(1.0),Angle(10),AtNominals(0))",
            "00017 ScanOnCurve(Closed(0), Format(X(),Y(),Z(),IJK(),tag,pi,pj,pk), Data(10.0,0.0,0.0,0,0,1,0,0,0,1))",
        ] {
            let command: Command = line.parse().unwrap_or_else(|e| panic!("{line}: {e}"));
            let again: Command = command.to_string().parse().unwrap();
            assert_eq!(again, command, "{line}");
        }
    }

    #[test]
    fn formats_canonically() {
        let command: Command = "00017 PtMeas( X(1) ,Y(2),IJK(0,0,1) )".parse().unwrap();
        assert_eq!(
            command.to_string(),
            "00017 PtMeas(X(1), Y(2), IJK(0, 0, 1))"
        );
        assert_eq!(command.name().as_str(), "PtMeas");
        assert_eq!(command.args().len(), 3);
    }

    #[test]
    fn enforces_the_column_rules() {
        assert_eq!(problem("0001 Home()"), (WireError::BadTag, 1));
        assert_eq!(
            problem("012345 GoTo(X(3.1))"),
            (WireError::MissingSpaceAfterTag, 6)
        );
        assert_eq!(problem("00001  Home()"), (WireError::IllegalSpace, 7));
        assert_eq!(problem("00001"), (WireError::MissingSpaceAfterTag, 6));
        assert_eq!(
            problem("00001 Home"),
            (
                WireError::Expected {
                    expected: "`(`",
                    found: None
                },
                11
            )
        );
        assert_eq!(
            problem("05401 GoTo(X(0.1))2"),
            (WireError::TrailingCharacters, 19)
        );
        assert_eq!(
            problem("05400 Errors from parseCommand"),
            (WireError::IllegalSpace, 13)
        );
    }

    #[test]
    fn matches_event_tags_to_fast_queue_commands() {
        assert_eq!(
            problem("E0000 AbortE()"),
            (WireError::UnsolicitedTagInCommand, 1)
        );
        let name = "AbortE".to_owned();
        assert_eq!(
            problem("05402 AbortE()"),
            (WireError::FastCommandWithoutEventTag { name }, 1)
        );
        let name = "GoTo".to_owned();
        assert_eq!(
            problem("E5403 GoTo(X(0.1))"),
            (WireError::EventTagOnNormalCommand { name }, 1)
        );
        assert!("E0001 GetErrStatusE()".parse::<Command>().is_ok());
    }

    #[test]
    fn rejects_illegal_characters_before_anything_else() {
        assert_eq!(
            problem("00001 Home()\t"),
            (WireError::IllegalCharacter(b'\t'), 13)
        );
        assert_eq!(
            problem("A2345 GoTo(X(\u{7f}))"),
            (WireError::IllegalCharacter(0x7F), 14)
        );
    }
}
