//! What can be wrong with an I++ DME line or value, and where in the line it was found.

use std::fmt::{self, Write as _};

/// What is wrong with a line or a value, independent of where it was found.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum WireError {
    #[error("illegal character {} (only space to `~` are allowed; CR LF only as the line end)", ByteName(*.0))]
    IllegalCharacter(u8),
    #[error("line over the {max}-byte limit ({len} bytes read before giving up on it)")]
    LineTooLong { len: usize, max: usize },
    #[error("stream ended in the middle of a line (no CR LF)")]
    UnterminatedLine,
    #[error("columns 1-5 must be a tag: 5 digits, or `E` and 4 digits")]
    BadTag,
    #[error("tag number {number} is outside {range}")]
    TagOutOfRange { number: u32, range: &'static str },
    #[error("column 6 must be a space")]
    MissingSpaceAfterTag,
    #[error("E0000 is reserved for unsolicited server events; a command cannot use it")]
    UnsolicitedTagInCommand,
    #[error(
        "E0000 marks unsolicited events; it cannot acknowledge (&) or complete (%) a transaction"
    )]
    UnsolicitedTagOnTransaction,
    #[error(
        "`{name}` ends in `E`, so it is a fast-queue command and needs an event tag (E0001-E9999)"
    )]
    FastCommandWithoutEventTag { name: String },
    #[error("`{name}` does not end in `E`, so it is not a fast-queue command and cannot use an event tag")]
    EventTagOnNormalCommand { name: String },
    #[error("column 7 must be one of & % # !, found {}", ByteName(*.0))]
    BadMarker(u8),
    #[error("column 8 must be a space")]
    MissingSpaceAfterMarker,
    #[error("expected {expected}, found {}", Found(*.found))]
    Expected {
        expected: &'static str,
        found: Option<u8>,
    },
    #[error("space not allowed here (only around `,` and `(` and before `)`)")]
    IllegalSpace,
    #[error("unexpected text after the end of the line's content")]
    TrailingCharacters,
    #[error("number has no digits")]
    NumberWithoutDigits,
    #[error("number has {digits} digits, more than the 16 allowed")]
    NumberTooManyDigits { digits: usize },
    #[error("number has two decimal points")]
    NumberTwoDecimalPoints,
    #[error("exponent must have one, two or three digits")]
    NumberBadExponent,
    #[error("number is too large for a 64-bit float")]
    NumberOutOfRange,
    #[error("NaN and infinities cannot be written as numbers")]
    NonFiniteNumber,
    #[error("string is empty or unterminated (needs `\"`, at least one character, `\"`)")]
    BadString,
    #[error(
        "{0:?} cannot be a string: it needs 1 or more characters from space to `~`, without `\"`"
    )]
    InvalidString(String),
    #[error("{0:?} is not a name: letters, then letters or digits, parts joined by `.`")]
    InvalidName(String),
    #[error("{0:?} is not a keyword: a letter, then letters or digits, and not an event tag")]
    InvalidKeyword(String),
    #[error("calls nested more than {max} deep")]
    NestingTooDeep { max: usize },
    #[error("a data response needs at least one item")]
    EmptyData,
    #[error(
        "data items must be all numbers, all strings or all calls; found {found} after {first}"
    )]
    MixedData {
        first: &'static str,
        found: &'static str,
    },
    #[error(
        "`{0}` is not `Error`: an error response is `Error(severity, code, \"command\", \"text\")`"
    )]
    NotAnErrorCall(String),
    #[error("error severity must be one digit")]
    SeverityNotOneDigit,
    #[error("error code must be four digits")]
    CodeNotFourDigits,
    #[error("error severity {0} is over 9")]
    SeverityOutOfRange(u8),
    #[error("error code {0} is over 9999")]
    CodeOutOfRange(u16),
}

/// A [`WireError`] found in a line: the problem, the 1-based column, and the line (shortened, with
/// non-printable bytes escaped) so that a log says what was received.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{problem} (column {column} of `{excerpt}`)")]
pub struct LineError {
    problem: WireError,
    column: usize,
    excerpt: String,
}

/// How many bytes of the offending line an error keeps: enough to recognise the line in a log, short
/// enough that a 64 KiB garbage line does not flood it.
const EXCERPT_LEN: usize = 72;

impl LineError {
    /// `column` is 1-based; the excerpt is the part of `line` around it.
    pub(crate) fn new(problem: WireError, line: &[u8], column: usize) -> Self {
        LineError {
            problem,
            column,
            excerpt: excerpt(line, column),
        }
    }

    /// What is wrong.
    pub fn problem(&self) -> &WireError {
        &self.problem
    }

    /// The 1-based column where the problem was found.
    pub fn column(&self) -> usize {
        self.column
    }

    /// The offending line, shortened around the column, non-printable bytes written as `\xNN`.
    pub fn excerpt(&self) -> &str {
        &self.excerpt
    }
}

fn excerpt(line: &[u8], column: usize) -> String {
    let start = if line.len() <= EXCERPT_LEN {
        0
    } else {
        column
            .saturating_sub(EXCERPT_LEN / 2)
            .min(line.len() - EXCERPT_LEN)
    };
    let end = (start + EXCERPT_LEN).min(line.len());
    let mut out = String::new();
    if start > 0 {
        out.push_str("...");
    }
    for &byte in &line[start..end] {
        if (b' '..=b'~').contains(&byte) {
            out.push(char::from(byte));
        } else {
            // Writing to a String cannot fail.
            let _ = write!(out, "\\x{byte:02X}");
        }
    }
    if end < line.len() {
        out.push_str("...");
    }
    out
}

/// A byte in an error message: printable ones quoted, others as hex.
struct ByteName(u8);

impl fmt::Display for ByteName {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.0 {
            b' ' => f.write_str("a space"),
            b'!'..=b'~' => write!(f, "`{}`", char::from(self.0)),
            byte => write!(f, "byte 0x{byte:02X}"),
        }
    }
}

/// The byte a parser found instead of what it expected, or the end of the line.
struct Found(Option<u8>);

impl fmt::Display for Found {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.0 {
            Some(byte) => ByteName(byte).fmt(f),
            None => f.write_str("end of line"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn message_names_problem_column_and_text() {
        let error = LineError::new(WireError::MissingSpaceAfterTag, b"00001Home()", 6);
        assert_eq!(
            error.to_string(),
            "column 6 must be a space (column 6 of `00001Home()`)"
        );
    }

    #[test]
    fn excerpt_escapes_garbage_and_shortens_long_lines() {
        let error = LineError::new(WireError::IllegalCharacter(0xFF), b"00001 Home(\xFF)", 12);
        assert_eq!(error.excerpt(), "00001 Home(\\xFF)");
        assert!(error.to_string().contains("byte 0xFF"));

        let long = [b'x'; 1000];
        let error = LineError::new(WireError::TrailingCharacters, &long, 500);
        assert_eq!(
            error.excerpt(),
            format!("...{}...", "x".repeat(EXCERPT_LEN))
        );
        let at_start = LineError::new(WireError::TrailingCharacters, &long, 1);
        assert_eq!(
            at_start.excerpt(),
            format!("{}...", "x".repeat(EXCERPT_LEN))
        );
    }

    #[test]
    fn expected_names_what_was_found() {
        let error = WireError::Expected {
            expected: "`(`",
            found: None,
        };
        assert_eq!(error.to_string(), "expected `(`, found end of line");
        let error = WireError::Expected {
            expected: "`(`",
            found: Some(b'x'),
        };
        assert_eq!(error.to_string(), "expected `(`, found `x`");
    }
}
