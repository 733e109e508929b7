//! Arguments and calls: the values inside a command's parentheses and in data responses.

use std::fmt;

use super::{EventTag, Keyword, Name, Number, WireString};

/// How deeply calls may nest, counting the command's own parentheses as 1. The deepest form in the spec
/// is 3 (`ScanOnCurve(Format(X(), ...), ...)`); the cap keeps a line of 64 KiB of `(` from recursing the
/// parser (and the drop of the value) tens of thousands of frames deep.
pub const MAX_NESTING: usize = 8;

/// One argument.
#[derive(Debug, Clone, PartialEq)]
pub enum Arg {
    /// `12.5`, `-1E3`
    Number(Number),
    /// `"Probe1"`
    String(WireString),
    /// `E0553`, as in `StopDaemon(E0553)`
    EventTag(EventTag),
    /// `MachineCsy`
    Keyword(Keyword),
    /// `X(12.5)`, `IJK(0, 0, 1)`, `Tool.PtMeasPar.Speed()`, `Format(X(), Y(), Z(), IJK(), tag)`
    Call(Call),
}

/// A name with a parenthesised argument list: `X(1)`, `Tool.GoToPar.Speed(25)`, `DMEVersion("1.4")`.
///
/// The spec's grammar only gives numbers to properties, but its own `ScanOnCurve(Format(X(), ...))` and the
/// replies `Tool.Name("Probe1")` and `Tool.CollisionVolume(OBB, ...)` need any argument, so a call takes any.
#[derive(Debug, Clone, PartialEq)]
pub struct Call {
    /// `X`, `Tool.GoToPar.Speed`
    pub name: Name,
    /// What is inside the parentheses.
    pub args: Vec<Arg>,
}

impl Call {
    /// The call of `name` with `args`.
    pub fn new(name: Name, args: Vec<Arg>) -> Self {
        Call { name, args }
    }

    /// Levels of parentheses: 1 for `X(1)`, 2 for `GoTo(X(1))`.
    pub(crate) fn nesting(&self) -> usize {
        1 + args_nesting(&self.args)
    }
}

/// The deepest nesting among `args`; 0 when none is a call.
pub(crate) fn args_nesting(args: &[Arg]) -> usize {
    args.iter()
        .map(|arg| match arg {
            Arg::Call(call) => call.nesting(),
            _ => 0,
        })
        .max()
        .unwrap_or(0)
}

/// Writes items separated by `, ` as in the spec's examples (`X(99.93), Y(17.148)`).
pub(crate) fn write_list<T: fmt::Display>(f: &mut fmt::Formatter<'_>, items: &[T]) -> fmt::Result {
    for (index, item) in items.iter().enumerate() {
        if index > 0 {
            f.write_str(", ")?;
        }
        item.fmt(f)?;
    }
    Ok(())
}

impl fmt::Display for Arg {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Arg::Number(number) => number.fmt(f),
            Arg::String(string) => string.fmt(f),
            Arg::EventTag(tag) => tag.fmt(f),
            Arg::Keyword(keyword) => keyword.fmt(f),
            Arg::Call(call) => call.fmt(f),
        }
    }
}

impl fmt::Display for Call {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}(", self.name)?;
        write_list(f, &self.args)?;
        f.write_str(")")
    }
}

impl From<Number> for Arg {
    fn from(number: Number) -> Self {
        Arg::Number(number)
    }
}

impl From<WireString> for Arg {
    fn from(string: WireString) -> Self {
        Arg::String(string)
    }
}

impl From<EventTag> for Arg {
    fn from(tag: EventTag) -> Self {
        Arg::EventTag(tag)
    }
}

impl From<Keyword> for Arg {
    fn from(keyword: Keyword) -> Self {
        Arg::Keyword(keyword)
    }
}

impl From<Call> for Arg {
    fn from(call: Call) -> Self {
        Arg::Call(call)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn call(name: &str, args: Vec<Arg>) -> Call {
        Call::new(Name::new(name).unwrap(), args)
    }

    fn number(value: f64) -> Arg {
        Number::from_f64(value).unwrap().into()
    }

    #[test]
    fn formats_like_the_spec_examples() {
        let ijk = call("IJK", vec![number(0.0), number(0.0), number(1.0)]);
        let goto = call(
            "PtMeas",
            vec![call("X", vec![number(99.93)]).into(), ijk.into()],
        );
        assert_eq!(goto.to_string(), "PtMeas(X(99.93), IJK(0, 0, 1))");
        let mixed = call(
            "Tool.CollisionVolume",
            vec![Keyword::new("OBB").unwrap().into(), number(1.5)],
        );
        assert_eq!(mixed.to_string(), "Tool.CollisionVolume(OBB, 1.5)");
        let stop = call("StopDaemon", vec![EventTag::new(553).unwrap().into()]);
        assert_eq!(stop.to_string(), "StopDaemon(E0553)");
        let tool = call(
            "ChangeTool",
            vec![WireString::new("Probe1").unwrap().into()],
        );
        assert_eq!(tool.to_string(), "ChangeTool(\"Probe1\")");
        assert_eq!(call("Home", vec![]).to_string(), "Home()");
    }

    #[test]
    fn nesting_counts_parentheses() {
        let x = call("X", vec![]);
        assert_eq!(x.nesting(), 1);
        let format = call("Format", vec![x.into()]);
        let scan = call("ScanOnCurve", vec![format.into(), number(1.0)]);
        assert_eq!(scan.nesting(), 3);
    }
}
