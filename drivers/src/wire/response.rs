//! Response lines, server to client (spec 6.2.2.2): `Tag " " Marker [" " payload]`, the marker in column 7.

use std::fmt;
use std::str::FromStr;

use super::cursor::{check_characters, Cursor, Parsed};
use super::value::{write_list, MAX_NESTING};
use super::{Call, LineError, Number, Tag, WireError, WireString};

/// What column 7 of a response holds.
const MARKER: &str = "one of & % # ! in column 7";

/// One response line, e.g. `00004 # X(99.93), Y(17.148)` or `E0000 ! Error(3, 0500, "Stop", "Emergency stop")`.
#[derive(Debug, Clone, PartialEq)]
pub struct Response {
    tag: Tag,
    kind: ResponseKind,
}

/// What a response says, by the character in column 7.
#[derive(Debug, Clone, PartialEq)]
pub enum ResponseKind {
    /// `&`: the command was accepted; the client may send the next one.
    Ack,
    /// `#`: data.
    Data(Data),
    /// `%`: the transaction is complete.
    Complete,
    /// `!`: an error.
    Error(DeviceError),
}

/// The payload of a data response (spec `DataData`), by the kind of its items.
#[derive(Debug, Clone, PartialEq)]
pub enum Data {
    /// `10.0, 0.0, 1.5, ...`: scan points.
    Numbers(Vec<Number>),
    /// `"Speed", "Number"`: an enumerated property. NIST servers also send a single string (a tool name).
    Strings(Vec<WireString>),
    /// `X(1), Y(2), Z(3)` (a property list) or `DMEVersion("1.4")` (a method).
    Calls(Vec<Call>),
    /// `(1, 0, 0)`: the vectors NIST servers return for `AlignTool` and `AlignPart`; the spec does not
    /// spell their form out ("Returns vectors (same number as set)").
    Vector(Vec<Number>),
}

/// The payload of an error response: `Error(severity, code, "command", "text")` (spec 8.1).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DeviceError {
    severity: u8,
    code: u16,
    command: WireString,
    text: WireString,
}

impl Response {
    /// The response, if it may go on the wire: E0000 only on data and errors (it answers no transaction),
    /// data not empty, calls nested at most [`MAX_NESTING`] deep.
    pub fn new(tag: Tag, kind: ResponseKind) -> Result<Self, WireError> {
        match &kind {
            ResponseKind::Ack | ResponseKind::Complete if tag == Tag::Unsolicited => {
                return Err(WireError::UnsolicitedTagOnTransaction)
            }
            ResponseKind::Data(data) => data.check()?,
            _ => {}
        }
        Ok(Response { tag, kind })
    }

    /// Reads one line, without its CR LF.
    pub fn parse(line: &[u8]) -> Result<Self, LineError> {
        check_characters(line)?;
        let tag = Tag::parse(line).map_err(|problem| LineError::new(problem, line, 1))?;
        if line.get(5) != Some(&b' ') {
            return Err(LineError::new(WireError::MissingSpaceAfterTag, line, 6));
        }
        let marker = *line.get(6).ok_or_else(|| {
            LineError::new(
                WireError::Expected {
                    expected: MARKER,
                    found: None,
                },
                line,
                7,
            )
        })?;
        let kind = match marker {
            b'&' | b'%' => {
                Cursor::new(line, 7).expect_end()?;
                if marker == b'&' {
                    ResponseKind::Ack
                } else {
                    ResponseKind::Complete
                }
            }
            b'#' | b'!' => {
                if line.get(7) != Some(&b' ') {
                    return Err(LineError::new(WireError::MissingSpaceAfterMarker, line, 8));
                }
                let mut cursor = Cursor::new(line, 8);
                let kind = if marker == b'#' {
                    ResponseKind::Data(parse_data(&mut cursor)?)
                } else {
                    ResponseKind::Error(parse_error(&mut cursor)?)
                };
                cursor.expect_end()?;
                kind
            }
            other => return Err(LineError::new(WireError::BadMarker(other), line, 7)),
        };
        Response::new(tag, kind).map_err(|problem| LineError::new(problem, line, 1))
    }

    /// The tag: the transaction's, or E0000 for an unsolicited event.
    pub fn tag(&self) -> Tag {
        self.tag
    }

    /// What the response says.
    pub fn kind(&self) -> &ResponseKind {
        &self.kind
    }

    /// What the response says, taken out.
    pub fn into_kind(self) -> ResponseKind {
        self.kind
    }
}

impl Data {
    fn check(&self) -> Result<(), WireError> {
        let (empty, nesting) = match self {
            Data::Numbers(numbers) | Data::Vector(numbers) => (numbers.is_empty(), 0),
            Data::Strings(strings) => (strings.is_empty(), 0),
            Data::Calls(calls) => (
                calls.is_empty(),
                calls.iter().map(Call::nesting).max().unwrap_or(0),
            ),
        };
        if empty {
            Err(WireError::EmptyData)
        } else if nesting > MAX_NESTING {
            Err(WireError::NestingTooDeep { max: MAX_NESTING })
        } else {
            Ok(())
        }
    }
}

impl DeviceError {
    /// The error, if `severity` is one digit and `code` four.
    pub fn new(
        severity: u8,
        code: u16,
        command: WireString,
        text: WireString,
    ) -> Result<Self, WireError> {
        if severity > 9 {
            return Err(WireError::SeverityOutOfRange(severity));
        }
        if code > 9999 {
            return Err(WireError::CodeOutOfRange(code));
        }
        Ok(DeviceError {
            severity,
            code,
            command,
            text,
        })
    }

    /// 0 info, 1 warning, 2 error the client can repair, 3 error needing the user, 9 fatal. From 2 up the
    /// server aborts pending transactions and wants `ClearAllErrors()`.
    pub fn severity(&self) -> u8 {
        self.severity
    }

    /// The error number, such as 0500 (emergency stop) or 2504 (collision); spec 8.2 lists them.
    pub fn code(&self) -> u16 {
        self.code
    }

    /// The method that reported the error (NIST servers put the failing command line here).
    pub fn command(&self) -> &str {
        self.command.as_str()
    }

    /// The error's text, spec 8.2's for the code.
    pub fn text(&self) -> &str {
        self.text.as_str()
    }
}

/// The kinds of data item; the first item's kind is the kind of all.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum ItemKind {
    Number,
    String,
    Call,
    Vector,
}

impl ItemKind {
    /// The kind of the item starting with `byte`.
    fn of(byte: Option<u8>) -> Option<Self> {
        match byte? {
            b'+' | b'-' | b'.' | b'0'..=b'9' => Some(ItemKind::Number),
            b'"' => Some(ItemKind::String),
            b'(' => Some(ItemKind::Vector),
            byte if byte.is_ascii_alphabetic() => Some(ItemKind::Call),
            _ => None,
        }
    }

    fn described(self) -> &'static str {
        match self {
            ItemKind::Number => "a number",
            ItemKind::String => "a string",
            ItemKind::Call => "a call",
            ItemKind::Vector => "a vector",
        }
    }
}

/// The items after `# `, all of one kind as in the spec's `DataData :== NumData | PropData | Method |
/// PropertyList`, or NIST's parenthesised vector alone.
fn parse_data(cursor: &mut Cursor<'_>) -> Parsed<Data> {
    let kind = ItemKind::of(cursor.peek())
        .ok_or_else(|| cursor.unexpected("a number, string, call or `(`"))?;
    Ok(match kind {
        ItemKind::Number => Data::Numbers(items(cursor, kind, Cursor::number)?),
        ItemKind::String => Data::Strings(items(cursor, kind, Cursor::string)?),
        ItemKind::Call => Data::Calls(items(cursor, kind, data_call)?),
        ItemKind::Vector => Data::Vector(vector(cursor)?),
    })
}

/// Items of `kind` separated by `{s} "," {s}` up to the end of the line.
fn items<'a, T>(
    cursor: &mut Cursor<'a>,
    kind: ItemKind,
    item: impl Fn(&mut Cursor<'a>) -> Parsed<T>,
) -> Parsed<Vec<T>> {
    let mut items = vec![item(cursor)?];
    loop {
        cursor.skip_spaces_before(b",")?;
        if cursor.at_end() {
            return Ok(items);
        }
        cursor.expect(b',', "`,` or end of line")?;
        cursor.skip_spaces();
        match ItemKind::of(cursor.peek()) {
            Some(found) if found != kind => {
                let problem = WireError::MixedData {
                    first: kind.described(),
                    found: found.described(),
                };
                return Err(cursor.error(problem));
            }
            Some(_) => items.push(item(cursor)?),
            None => return Err(cursor.unexpected(kind.described())),
        }
    }
}

/// A call as a data item: `X(1)`, `Tool.Name("Probe1")`, `ChangeToolAction(Switch, X(0), Y(0), Z(-8))`.
fn data_call(cursor: &mut Cursor<'_>) -> Parsed<Call> {
    let name = cursor.name("a name")?;
    if !cursor.paren_follows() {
        return Err(cursor.unexpected("`(` after a name in data"));
    }
    let args = cursor.call_args(1)?;
    Ok(Call::new(name, args))
}

/// `"(" {s} Number {SCommaS Number} {s} ")"`.
fn vector(cursor: &mut Cursor<'_>) -> Parsed<Vec<Number>> {
    cursor.expect(b'(', "`(`")?;
    cursor.skip_spaces();
    let mut numbers = vec![cursor.number()?];
    loop {
        cursor.skip_spaces_before(b",)")?;
        if cursor.eat(b')') {
            return Ok(numbers);
        }
        cursor.expect(b',', "`,` or `)`")?;
        cursor.skip_spaces();
        numbers.push(cursor.number()?);
    }
}

/// `"Error" SLeftParenS F1 SCommaS F2 SCommaS F3 SCommaS Text SRightParen` after `! `.
///
/// F3 may also be a bare method name: spec 8.1 says it "doesn't contain spaces or special characters. So
/// there is no need for putting into \"\"", and its own examples (`Error(3, 2500, GoTo, ...)`) do that.
fn parse_error(cursor: &mut Cursor<'_>) -> Parsed<DeviceError> {
    let start = cursor.pos();
    let name = cursor.name("`Error`")?;
    if name.as_str() != "Error" {
        return Err(cursor.error_at(start, WireError::NotAnErrorCall(name.as_str().to_owned())));
    }
    cursor.skip_spaces_before(b"(")?;
    cursor.expect(b'(', "`(`")?;
    cursor.skip_spaces();
    let severity = digits_field(cursor, 1, WireError::SeverityNotOneDigit)?;
    comma(cursor)?;
    let code = digits_field(cursor, 4, WireError::CodeNotFourDigits)?;
    comma(cursor)?;
    let command = if cursor.peek() == Some(b'"') {
        cursor.string()?
    } else {
        let name_at = cursor.pos();
        let name = cursor.name("the reporting method")?;
        WireString::new(name.as_str()).map_err(|problem| cursor.error_at(name_at, problem))?
    };
    comma(cursor)?;
    let text = cursor.string()?;
    cursor.skip_spaces_before(b")")?;
    cursor.expect(b')', "`)`")?;
    let severity = u8::try_from(severity).expect("one digit");
    DeviceError::new(severity, code, command, text)
        .map_err(|problem| cursor.error_at(start, problem))
}

/// A field of exactly `len` plain digits (no sign, point or exponent).
fn digits_field(cursor: &mut Cursor<'_>, len: usize, problem: WireError) -> Parsed<u16> {
    let start = cursor.pos();
    let number = cursor
        .number()
        .map_err(|_| cursor.error_at(start, problem.clone()))?;
    let text = number.as_str();
    if text.len() != len || !text.bytes().all(|byte| byte.is_ascii_digit()) {
        return Err(cursor.error_at(start, problem));
    }
    Ok(text.parse().expect("at most four digits"))
}

/// `{s} "," {s}`.
fn comma(cursor: &mut Cursor<'_>) -> Parsed<()> {
    cursor.skip_spaces_before(b",")?;
    cursor.expect(b',', "`,`")?;
    cursor.skip_spaces();
    Ok(())
}

impl FromStr for Response {
    type Err = LineError;

    fn from_str(line: &str) -> Result<Self, LineError> {
        Response::parse(line.as_bytes())
    }
}

impl fmt::Display for Response {
    /// The line without its CR LF.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.kind {
            ResponseKind::Ack => write!(f, "{} &", self.tag),
            ResponseKind::Complete => write!(f, "{} %", self.tag),
            ResponseKind::Data(data) => write!(f, "{} # {data}", self.tag),
            ResponseKind::Error(error) => write!(f, "{} ! {error}", self.tag),
        }
    }
}

impl fmt::Display for Data {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Data::Numbers(numbers) => write_list(f, numbers),
            Data::Strings(strings) => write_list(f, strings),
            Data::Calls(calls) => write_list(f, calls),
            Data::Vector(numbers) => {
                f.write_str("(")?;
                write_list(f, numbers)?;
                f.write_str(")")
            }
        }
    }
}

impl fmt::Display for DeviceError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "Error({}, {:04}, {}, {})",
            self.severity, self.code, self.command, self.text
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(line: &str) -> Response {
        line.parse().unwrap_or_else(|e| panic!("{line}: {e}"))
    }

    fn problem(line: &str) -> (WireError, usize) {
        let error = line.parse::<Response>().unwrap_err();
        (error.problem().clone(), error.column())
    }

    fn round_trips(line: &str) {
        let response = parse(line);
        assert_eq!(parse(&response.to_string()), response, "{line}");
    }

    #[test]
    fn reads_ack_complete_and_the_data_kinds() {
        assert_eq!(parse("00001 &").kind(), &ResponseKind::Ack);
        assert_eq!(parse("00001 %").kind(), &ResponseKind::Complete);
        assert!(
            matches!(parse("00017 # 10.0,0.0,1.5,0.001").kind(), ResponseKind::Data(Data::Numbers(n)) if n.len() == 4)
        );
        assert!(
            matches!(parse("00301 # \"Speed\", \"Number\"").kind(), ResponseKind::Data(Data::Strings(s)) if s.len() == 2)
        );
        assert!(
            matches!(parse("00004 # X(99.93), Y(17.148)").kind(), ResponseKind::Data(Data::Calls(c)) if c.len() == 2)
        );
        assert!(
            matches!(parse("00101 # (1.0, 0.0, 0.0)").kind(), ResponseKind::Data(Data::Vector(v)) if v.len() == 3)
        );
        for line in [
            "00004 # X(99.93), Y(17.148)",
            "00501 # ChangeToolAction(Switch, X(0.00000), Y(0.00000), Z(-8.00000))",
            "01501 # Tool.CollisionVolume(OBB,20.0,20.0,1.0), Tool.Name(\"Probe1\")",
            "E0553 # X(50), Y(433), Z(520)",
            "E0000 # KeyPress(\"F1\")",
            "00102 # (1.0, 0.0, 0.0, 0.6, 0.0, 0.8)",
        ] {
            round_trips(line);
        }
    }

    #[test]
    fn formats_data_canonically() {
        assert_eq!(parse("00017 # 1,2 ,  3").to_string(), "00017 # 1, 2, 3");
        assert_eq!(parse("00101 # ( 1 ,0 )").to_string(), "00101 # (1, 0)");
    }

    #[test]
    fn reads_the_error_format() {
        let response =
            parse("00401 ! Error(2, 0513, \"00401 StopDaemon(E1234)\", \"Daemon does not exist\")");
        let ResponseKind::Error(error) = response.kind() else {
            panic!("not an error: {response}")
        };
        assert_eq!((error.severity(), error.code()), (2, 513));
        assert_eq!(
            (error.command(), error.text()),
            ("00401 StopDaemon(E1234)", "Daemon does not exist")
        );
        assert_eq!(
            response.to_string(),
            "00401 ! Error(2, 0513, \"00401 StopDaemon(E1234)\", \"Daemon does not exist\")"
        );
    }

    #[test]
    fn reads_an_unquoted_method_in_an_error() {
        let response =
            parse("00010 ! Error(3,1008, DoGoTo , \"Target position out of machine volume\")");
        assert_eq!(
            response.to_string(),
            "00010 ! Error(3, 1008, \"DoGoTo\", \"Target position out of machine volume\")"
        );
    }

    #[test]
    fn reads_an_unsolicited_emergency_stop() {
        let response = parse("E0000 ! Error(3, 0500, \"HealthCheck\", \"Emergency stop\")");
        assert_eq!(response.tag(), Tag::Unsolicited);
        assert!(
            matches!(response.into_kind(), ResponseKind::Error(error) if error.code() == 500 && error.severity() == 3)
        );
    }

    #[test]
    fn rejects_malformed_errors() {
        // parserResErrors.res 00601-00604.
        assert_eq!(
            problem("00601 ! Error(1, 0512, \"start error messages from makeErrorResponse\")").0,
            WireError::Expected {
                expected: "`,`",
                found: Some(b')')
            }
        );
        assert_eq!(
            problem("00602 ! Tool(1, 0512, \"me\", \"text\")"),
            (WireError::NotAnErrorCall("Tool".into()), 9)
        );
        assert_eq!(
            problem("00603 ! Error(01, 0512, \"me\", \"text\")"),
            (WireError::SeverityNotOneDigit, 15)
        );
        assert_eq!(
            problem("00604 ! Error(1, 512, \"me\", \"text\")"),
            (WireError::CodeNotFourDigits, 18)
        );
        assert_eq!(
            problem("00604 ! Error(1, 5.12, \"me\", \"text\")"),
            (WireError::CodeNotFourDigits, 18)
        );
        assert_eq!(
            problem("00604 ! Error(1, 0512, \"me\", text)").0,
            WireError::Expected {
                expected: "`\"`",
                found: Some(b't')
            }
        );
    }

    #[test]
    fn enforces_the_column_rules() {
        // parserResErrors.res 03101-03302 and the spec's "column 8 must be a space".
        assert_eq!(
            problem("03101 &start error messages"),
            (WireError::TrailingCharacters, 8)
        );
        assert_eq!(problem("03102 %oops"), (WireError::TrailingCharacters, 8));
        assert_eq!(problem("03103 $ X(3)"), (WireError::BadMarker(b'$'), 7));
        assert_eq!(
            problem("03104 #X(3)"),
            (WireError::MissingSpaceAfterMarker, 8)
        );
        assert_eq!(problem("03104 #"), (WireError::MissingSpaceAfterMarker, 8));
        assert_eq!(
            problem("03104 # "),
            (
                WireError::Expected {
                    expected: "a number, string, call or `(`",
                    found: None
                },
                9
            )
        );
        assert_eq!(problem("03104 #  X(3)"), (WireError::IllegalSpace, 9));
        assert_eq!(
            parse("03104 # X(3)  ").to_string(),
            "03104 # X(3)",
            "spaces at the end are tolerated"
        );
        assert_eq!(parse("03104 & ").to_string(), "03104 &");
        assert_eq!(problem("03302# X(3)"), (WireError::MissingSpaceAfterTag, 6));
        assert_eq!(problem("033A1 # X(3)"), (WireError::BadTag, 1));
        let missing = WireError::Expected {
            expected: MARKER,
            found: None,
        };
        assert_eq!(problem("00001 "), (missing, 7));
    }

    #[test]
    fn keeps_e0000_for_events() {
        assert_eq!(
            problem("E0000 &"),
            (WireError::UnsolicitedTagOnTransaction, 1)
        );
        assert_eq!(
            problem("E0000 %"),
            (WireError::UnsolicitedTagOnTransaction, 1)
        );
        assert!(matches!(
            parse("E0000 # GoTo(X(1), Y(2))").kind(),
            ResponseKind::Data(_)
        ));
        assert!(matches!(parse("E0001 &").tag(), Tag::Event(tag) if tag.number() == 1));
    }

    #[test]
    fn rejects_mixed_or_bare_data() {
        let mixed = WireError::MixedData {
            first: "a string",
            found: "a number",
        };
        assert_eq!(problem("00501 # \"start\", 30"), (mixed, 18));
        assert_eq!(
            problem("02802 # IsHomedic"),
            (
                WireError::Expected {
                    expected: "`(` after a name in data",
                    found: None
                },
                18
            )
        );
        assert_eq!(
            problem("00101 # (1), (2)"),
            (WireError::TrailingCharacters, 12)
        );
        assert_eq!(
            problem("02402 # 3,,3,").0,
            WireError::Expected {
                expected: "a number",
                found: Some(b',')
            }
        );
        assert_eq!(
            problem("02402 # 3,3,").0,
            WireError::Expected {
                expected: "a number",
                found: None
            }
        );
    }

    #[test]
    fn constructors_check_what_parsing_checks() {
        let text = WireString::new("Emergency stop").unwrap();
        let command = WireString::new("Stop").unwrap();
        assert_eq!(
            DeviceError::new(10, 500, command.clone(), text.clone()),
            Err(WireError::SeverityOutOfRange(10))
        );
        assert_eq!(
            DeviceError::new(3, 10_000, command.clone(), text.clone()),
            Err(WireError::CodeOutOfRange(10_000))
        );
        let stop = DeviceError::new(3, 500, command, text).unwrap();
        assert_eq!(
            stop.to_string(),
            "Error(3, 0500, \"Stop\", \"Emergency stop\")"
        );
        assert_eq!(
            Response::new(Tag::Unsolicited, ResponseKind::Ack),
            Err(WireError::UnsolicitedTagOnTransaction)
        );
        assert_eq!(
            Response::new(Tag::Unsolicited, ResponseKind::Data(Data::Numbers(vec![]))),
            Err(WireError::EmptyData)
        );
        assert!(Response::new(Tag::Unsolicited, ResponseKind::Error(stop)).is_ok());
    }
}
