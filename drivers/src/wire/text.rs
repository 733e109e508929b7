//! Strings, names and keywords (spec 6.1.4.2: `String`, `Name`, `BasicName`).

use std::fmt;

use super::{EventTag, WireError};

/// A string argument: one or more characters from space to `~`, without `"`. Displays with its quotes.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct WireString(Box<str>);

/// A method or property name: letters then letters or digits, parts joined by `.` (`GoTo`,
/// `Tool.PtMeasPar.Speed`; dotted command names are the spec's company extensions, 9.1).
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct Name(Box<str>);

/// A bare word argument such as `MachineCsy`, `Switch` or `OBB`: a letter then letters or digits.
/// `E` and four digits other than E0000 is an [`EventTag`], so it is not a keyword.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct Keyword(Box<str>);

impl WireString {
    /// The string with this content (without quotes).
    pub fn new(content: &str) -> Result<Self, WireError> {
        let valid = !content.is_empty() && content.bytes().all(is_string_char);
        if valid {
            Ok(WireString(content.into()))
        } else {
            Err(WireError::InvalidString(content.to_owned()))
        }
    }

    /// The content, without quotes.
    pub fn as_str(&self) -> &str {
        &self.0
    }
}

impl Name {
    /// The name, if `text` is one.
    pub fn new(text: &str) -> Result<Self, WireError> {
        if scan_name(text.as_bytes()) == Ok(text.len()) {
            Ok(Name(text.into()))
        } else {
            Err(WireError::InvalidName(text.to_owned()))
        }
    }

    /// The name's text.
    pub fn as_str(&self) -> &str {
        &self.0
    }
}

impl Keyword {
    /// The keyword, if `text` is one.
    pub fn new(text: &str) -> Result<Self, WireError> {
        let bytes = text.as_bytes();
        if scan_basic_name(bytes) == bytes.len()
            && !bytes.is_empty()
            && EventTag::from_text(bytes).is_none()
        {
            Ok(Keyword(text.into()))
        } else {
            Err(WireError::InvalidKeyword(text.to_owned()))
        }
    }

    /// The keyword's text.
    pub fn as_str(&self) -> &str {
        &self.0
    }
}

/// A character allowed inside a string: space to `~` except `"`.
pub(crate) fn is_string_char(byte: u8) -> bool {
    (b' '..=b'~').contains(&byte) && byte != b'"'
}

/// Length of the `BasicName` (a letter, then letters or digits) at the start of `input`; 0 if none.
pub(crate) fn scan_basic_name(input: &[u8]) -> usize {
    match input.first() {
        Some(first) if first.is_ascii_alphabetic() => {
            1 + input[1..]
                .iter()
                .take_while(|b| b.is_ascii_alphanumeric())
                .count()
        }
        _ => 0,
    }
}

/// Length of the `Name` (basic names joined by `.`) at the start of `input`, or the offset of the byte
/// where a name part was expected and is missing.
pub(crate) fn scan_name(input: &[u8]) -> Result<usize, usize> {
    let mut end = 0;
    loop {
        match scan_basic_name(&input[end..]) {
            0 => return Err(end),
            len => end += len,
        }
        if input.get(end) != Some(&b'.') {
            return Ok(end);
        }
        end += 1;
    }
}

impl fmt::Display for WireString {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "\"{}\"", self.0)
    }
}

impl fmt::Display for Name {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl fmt::Display for Keyword {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strings_need_printable_content_without_quotes() {
        assert_eq!(
            WireString::new("Probe 1 ~!#").unwrap().to_string(),
            "\"Probe 1 ~!#\""
        );
        assert!(WireString::new("").is_err());
        assert!(WireString::new("say \"hi\"").is_err());
        assert!(WireString::new("tab\there").is_err());
        assert!(WireString::new("é").is_err());
    }

    #[test]
    fn names_are_dotted_basic_names() {
        assert!(Name::new("GoTo").is_ok());
        assert!(Name::new("Tool.PtMeasPar.Speed").is_ok());
        assert!(Name::new("CZ.Scan2").is_ok());
        for bad in [
            "", "2X", "Tool.", ".Tool", "Tool..A", "Tool. A", "Go To", "X_1",
        ] {
            assert!(Name::new(bad).is_err(), "{bad:?}");
        }
    }

    #[test]
    fn keywords_are_undotted_and_not_event_tags() {
        assert!(Keyword::new("MachineCsy").is_ok());
        assert!(
            Keyword::new("E0000").is_ok(),
            "E0000 is not an ETag in the grammar, so it is a BasicName"
        );
        assert!(Keyword::new("E12345").is_ok());
        for bad in ["", "E1234", "Tool.A", "1st"] {
            assert!(Keyword::new(bad).is_err(), "{bad:?}");
        }
    }

    #[test]
    fn scan_name_reports_where_a_part_is_missing() {
        assert_eq!(scan_name(b"Tool.A(1)"), Ok(6));
        assert_eq!(scan_name(b"Tool. A"), Err(5));
        assert_eq!(scan_name(b"(1)"), Err(0));
    }
}
