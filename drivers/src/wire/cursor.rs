//! The shared reader for the text after the tag: names, arguments, calls, strings and numbers, with the
//! spec's rule on optional spaces: "Any number of optional spaces may appear (1) before or after a comma,
//! (2) before or after a left parenthesis (3) before a right parenthesis. Optional spaces may appear nowhere
//! else."
//!
//! One tolerance beyond that: spaces at the end of a line are ignored. NIST's PtMeasE.res, which its
//! description calls valid, has such lines, and dropping a whole measurement over them helps no one.

use super::text::{is_string_char, scan_basic_name, scan_name};
use super::value::MAX_NESTING;
use super::{Arg, Call, EventTag, Keyword, LineError, Name, Number, WireError, WireString};

/// A position in one line (without its CR LF).
pub(crate) struct Cursor<'a> {
    line: &'a [u8],
    pos: usize,
}

pub(crate) type Parsed<T> = Result<T, LineError>;

impl<'a> Cursor<'a> {
    pub(crate) fn new(line: &'a [u8], pos: usize) -> Self {
        Cursor { line, pos }
    }

    pub(crate) fn pos(&self) -> usize {
        self.pos
    }

    pub(crate) fn peek(&self) -> Option<u8> {
        self.line.get(self.pos).copied()
    }

    pub(crate) fn at_end(&self) -> bool {
        self.pos >= self.line.len()
    }

    pub(crate) fn skip_spaces(&mut self) {
        while self.peek() == Some(b' ') {
            self.pos += 1;
        }
    }

    /// Skips spaces that the grammar allows only before one of `allowed` (`{s} ","`, `{s} ")"`,
    /// `{s} "("`) or at the end of the line: if something else follows them, the spaces are the error.
    pub(crate) fn skip_spaces_before(&mut self, allowed: &[u8]) -> Parsed<()> {
        let start = self.pos;
        self.skip_spaces();
        match self.peek() {
            Some(byte) if self.pos > start && !allowed.contains(&byte) => {
                Err(self.error_at(start, WireError::IllegalSpace))
            }
            _ => Ok(()),
        }
    }

    /// An error at byte offset `pos` of the line.
    pub(crate) fn error_at(&self, pos: usize, problem: WireError) -> LineError {
        LineError::new(problem, self.line, pos + 1)
    }

    /// An error at the current position.
    pub(crate) fn error(&self, problem: WireError) -> LineError {
        self.error_at(self.pos, problem)
    }

    /// The byte here is not what the grammar allows; a space gets its own message since that is the usual
    /// slip (`X(+1.2 E2)`, `Tool. A()`).
    pub(crate) fn unexpected(&self, expected: &'static str) -> LineError {
        match self.peek() {
            Some(b' ') => self.error(WireError::IllegalSpace),
            found => self.error(WireError::Expected { expected, found }),
        }
    }

    /// Consumes `byte` if it comes next.
    pub(crate) fn eat(&mut self, byte: u8) -> bool {
        let found = self.peek() == Some(byte);
        self.pos += usize::from(found);
        found
    }

    /// Consumes `byte` or fails naming `expected`.
    pub(crate) fn expect(&mut self, byte: u8, expected: &'static str) -> Parsed<()> {
        if self.eat(byte) {
            Ok(())
        } else {
            Err(self.unexpected(expected))
        }
    }

    /// Nothing but spaces may follow.
    pub(crate) fn expect_end(&mut self) -> Parsed<()> {
        self.skip_spaces();
        match self.peek() {
            None => Ok(()),
            Some(_) => Err(self.error(WireError::TrailingCharacters)),
        }
    }

    /// A dotted name.
    pub(crate) fn name(&mut self, expected: &'static str) -> Parsed<Name> {
        match scan_name(&self.line[self.pos..]) {
            Ok(len) => {
                let text = self.take_str(len);
                Ok(Name::new(text).expect("scanned text is a name"))
            }
            Err(offset) => {
                self.pos += offset;
                Err(self.unexpected(if offset == 0 {
                    expected
                } else {
                    "a name part after `.`"
                }))
            }
        }
    }

    /// The argument list of a call at parenthesis level `depth`: `{s} "(" {s} [Arg {SCommaS Arg}] {s} ")"`.
    pub(crate) fn call_args(&mut self, depth: usize) -> Parsed<Vec<Arg>> {
        if depth > MAX_NESTING {
            return Err(self.error(WireError::NestingTooDeep { max: MAX_NESTING }));
        }
        self.skip_spaces_before(b"(")?;
        self.expect(b'(', "`(`")?;
        self.skip_spaces();
        let mut args = Vec::new();
        if self.eat(b')') {
            return Ok(args);
        }
        loop {
            args.push(self.arg(depth)?);
            self.skip_spaces_before(b",)")?;
            if self.eat(b')') {
                return Ok(args);
            }
            self.expect(b',', "`,` or `)`")?;
            self.skip_spaces();
        }
    }

    /// One argument inside a call at parenthesis level `depth`: `String | Number | Call | ETag | BasicName`.
    fn arg(&mut self, depth: usize) -> Parsed<Arg> {
        match self.peek() {
            Some(b'"') => self.string().map(Arg::String),
            Some(b'+' | b'-' | b'.' | b'0'..=b'9') => self.number().map(Arg::Number),
            Some(byte) if byte.is_ascii_alphabetic() => self.word_or_call(depth),
            _ => Err(self.unexpected("an argument")),
        }
    }

    /// A call if a `(` follows the name, else an event tag or keyword (which cannot be dotted).
    fn word_or_call(&mut self, depth: usize) -> Parsed<Arg> {
        let start = self.pos;
        let name = self.name("a name")?;
        if self.paren_follows() {
            let args = self.call_args(depth + 1)?;
            return Ok(Arg::Call(Call::new(name, args)));
        }
        let text = name.as_str();
        if let Some(tag) = EventTag::from_text(text.as_bytes()) {
            return Ok(Arg::EventTag(tag));
        }
        if scan_basic_name(text.as_bytes()) != text.len() {
            return Err(self.unexpected("`(` after a dotted name"));
        }
        Ok(Arg::Keyword(
            Keyword::new(text).map_err(|problem| self.error_at(start, problem))?,
        ))
    }

    /// Whether `{s} "("` comes next, without consuming anything.
    pub(crate) fn paren_follows(&self) -> bool {
        self.line[self.pos..].iter().find(|&&byte| byte != b' ') == Some(&b'(')
    }

    /// `"` one or more string characters `"`.
    pub(crate) fn string(&mut self) -> Parsed<WireString> {
        let start = self.pos;
        self.expect(b'"', "`\"`")?;
        let len = self.line[self.pos..]
            .iter()
            .take_while(|&&byte| is_string_char(byte))
            .count();
        let content = self.take_str(len);
        if content.is_empty() || self.peek() != Some(b'"') {
            return Err(self.error_at(start, WireError::BadString));
        }
        self.pos += 1;
        Ok(WireString::new(content).expect("scanned text is a string"))
    }

    /// A number; the byte after it must be able to follow a number.
    pub(crate) fn number(&mut self) -> Parsed<Number> {
        let start = self.pos;
        let (number, len) = Number::scan(&self.line[start..])
            .map_err(|(problem, offset)| self.error_at(start + offset, problem))?;
        self.pos += len;
        Ok(number)
    }

    /// Consumes `len` bytes, already checked to be ASCII, and returns them as text.
    fn take_str(&mut self, len: usize) -> &'a str {
        let text = &self.line[self.pos..self.pos + len];
        self.pos += len;
        std::str::from_utf8(text).expect("line was checked to be ASCII")
    }
}

/// Fails at the first byte that is not space to `~` (spec 6.1.1: such a line gets error 0007).
pub(crate) fn check_characters(line: &[u8]) -> Parsed<()> {
    match line.iter().position(|byte| !(b' '..=b'~').contains(byte)) {
        None => Ok(()),
        Some(pos) => Err(LineError::new(
            WireError::IllegalCharacter(line[pos]),
            line,
            pos + 1,
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn args(text: &str) -> Parsed<Vec<Arg>> {
        let mut cursor = Cursor::new(text.as_bytes(), 0);
        let args = cursor.call_args(1)?;
        cursor.expect_end()?;
        Ok(args)
    }

    fn problem(text: &str) -> WireError {
        args(text).unwrap_err().problem().clone()
    }

    #[test]
    fn reads_every_kind_of_argument() {
        let parsed = args(r#"(1.5, "Probe1", E0553, MachineCsy, Tool.A(2), X())"#).unwrap();
        let shown: Vec<String> = parsed.iter().map(ToString::to_string).collect();
        assert_eq!(
            shown,
            [
                "1.5",
                "\"Probe1\"",
                "E0553",
                "MachineCsy",
                "Tool.A(2)",
                "X()"
            ]
        );
        assert!(matches!(parsed[2], Arg::EventTag(_)));
        assert!(matches!(parsed[3], Arg::Keyword(_)));
    }

    #[test]
    fn allows_spaces_only_where_the_spec_does() {
        assert!(args("( X ( 1 ) , Y(2) )").is_ok());
        assert!(args("(  )").is_ok());
        assert!(
            args("(X(1))  ").is_ok(),
            "spaces at the end of the line are tolerated"
        );
        assert_eq!(
            problem("(X (1)2)"),
            WireError::Expected {
                expected: "`,` or `)`",
                found: Some(b'2')
            }
        );
        assert_eq!(problem("(X(+1.2 E2))"), WireError::IllegalSpace);
        assert_eq!(problem("(X(1) Y(2))"), WireError::IllegalSpace);
        assert_eq!(problem("(Tool. A())"), WireError::IllegalSpace);
    }

    #[test]
    fn rejects_malformed_lists() {
        assert_eq!(
            problem("(,)"),
            WireError::Expected {
                expected: "an argument",
                found: Some(b',')
            }
        );
        assert_eq!(
            problem("(1,)"),
            WireError::Expected {
                expected: "an argument",
                found: Some(b')')
            }
        );
        assert_eq!(
            problem("(X(1)"),
            WireError::Expected {
                expected: "`,` or `)`",
                found: None
            }
        );
        assert_eq!(
            problem("(X(1) "),
            WireError::Expected {
                expected: "`,` or `)`",
                found: None
            }
        );
        assert_eq!(
            problem("(0\"oops\"-1)"),
            WireError::Expected {
                expected: "`,` or `)`",
                found: Some(b'"')
            }
        );
        assert_eq!(
            problem("(Tool.A)"),
            WireError::Expected {
                expected: "`(` after a dotted name",
                found: Some(b')')
            }
        );
        assert_eq!(
            problem("(X(#))"),
            WireError::Expected {
                expected: "an argument",
                found: Some(b'#')
            }
        );
        assert_eq!(
            problem("(X()())"),
            WireError::Expected {
                expected: "`,` or `)`",
                found: Some(b'(')
            }
        );
    }

    #[test]
    fn rejects_bad_strings_where_they_start() {
        let error = args("(\"\")").unwrap_err();
        assert_eq!(
            (error.problem(), error.column()),
            (&WireError::BadString, 2)
        );
        assert_eq!(problem("(\"hello)"), WireError::BadString);
    }

    #[test]
    fn caps_nesting() {
        let deep = format!(
            "{}{}",
            "X(".repeat(MAX_NESTING - 1),
            ")".repeat(MAX_NESTING)
        );
        assert!(args(&format!("({deep}")).is_ok());
        let too_deep = format!(
            "({}{}",
            "X(".repeat(MAX_NESTING),
            ")".repeat(MAX_NESTING + 1)
        );
        assert_eq!(
            problem(&too_deep),
            WireError::NestingTooDeep { max: MAX_NESTING }
        );
    }

    #[test]
    fn finds_illegal_characters() {
        let error = check_characters(b"00001 Home()\r").unwrap_err();
        assert_eq!(
            (error.problem(), error.column()),
            (&WireError::IllegalCharacter(b'\r'), 13)
        );
        assert!(check_characters(b"00001 ChangeTool(\"~ !\")").is_ok());
    }
}
