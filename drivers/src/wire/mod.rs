//! Typed I++ DME 1.4.3 lines and their exact text form (spec section 6.1.4.2, "Syntax").
//!
//! Parsing is strict about the spec's layout: tag in columns 1-5, a space in column 6, the command (or the
//! response marker `&` `%` `#` `!`) from column 7, spaces only around `,` and `(` and before `)`, numbers of at
//! most 16 digits with an exponent of at most 3 digits, strings of printable ASCII without `"`. Where NIST's
//! valid test files or the spec's own examples break its grammar, the parser follows them, and says so
//! where it does (spaces at the end of a line, any argument inside a property's parentheses, an unquoted
//! method name in an error, NIST's `(1, 0, 0)` vectors).
//! It checks the syntax of every line, not what a particular command means: `AbortE(3)` is a well-formed line
//! (the argument count of `AbortE` is for the layer that knows the commands).
//!
//! Every value here formats (`Display`) to the text the spec describes and parses back to an equal value.
//! Leaf values (tags, numbers, names, strings) are checked when built, and whole lines are checked by
//! [`Command::new`] and [`Response::new`], so a value that exists is a value that can go on the wire.

mod command;
mod cursor;
mod error;
mod number;
mod response;
mod tag;
mod text;
mod value;

pub use command::Command;
pub use error::{LineError, WireError};
pub use number::Number;
pub use response::{Data, DeviceError, Response, ResponseKind};
pub use tag::{CommandTag, EventTag, Tag};
pub use text::{Keyword, Name, WireString};
pub use value::{Arg, Call, MAX_NESTING};
