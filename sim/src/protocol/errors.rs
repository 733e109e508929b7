//! The spec's error codes (8.2) with their default severities and texts, as response lines.

use zeroset_drivers::wire::{DeviceError, Response, ResponseKind, Tag, WireString};

/// Error codes the simulator reports, from spec 8.2.
pub mod code {
    pub const ILLEGAL_TAG: u16 = 1;
    pub const NO_SPACE_AT_6: u16 = 2;
    pub const TRANSACTION_ABORTED: u16 = 6;
    pub const ILLEGAL_CHARACTER: u16 = 7;
    pub const PROTOCOL_ERROR: u16 = 8;
    pub const EMERGENCY_STOP: u16 = 500;
    pub const UNSUPPORTED_COMMAND: u16 = 501;
    pub const INCORRECT_ARGUMENTS: u16 = 502;
    pub const ARGUMENT_OUT_OF_RANGE: u16 = 504;
    pub const ILLEGAL_COMMAND: u16 = 507;
    pub const BAD_CONTEXT: u16 = 508;
    pub const BAD_ARGUMENT: u16 = 509;
    pub const BAD_PROPERTY: u16 = 510;
    pub const ERROR_PROCESSING_METHOD: u16 = 511;
    pub const DAEMON_DOES_NOT_EXIST: u16 = 513;
    pub const USE_CLEAR_ALL_ERRORS: u16 = 514;
    pub const DAEMON_ALREADY_EXISTS: u16 = 515;
    pub const NO_TOUCH: u16 = 1003;
    pub const SURFACE_NOT_FOUND: u16 = 1006;
    pub const VECTOR_HAS_NO_NORM: u16 = 1010;
    pub const TOOL_NOT_FOUND: u16 = 1502;
    pub const TOOL_NOT_DEFINED: u16 = 1503;
    pub const PROBE_DOES_NOT_ALLOW: u16 = 2002;
    pub const MACHINE_LIMIT: u16 = 2500;
    pub const COLLISION: u16 = 2504;
}

/// Default severity and text of a code (spec 8.2).
fn describe(code: u16) -> (u8, &'static str) {
    match code {
        code::ILLEGAL_TAG => (2, "Illegal tag"),
        code::NO_SPACE_AT_6 => (2, "No space at pos. 6"),
        code::TRANSACTION_ABORTED => (2, "Transaction aborted (Use ClearAllErrors To Continue)"),
        code::ILLEGAL_CHARACTER => (3, "Illegal character"),
        code::PROTOCOL_ERROR => (3, "Protocol error"),
        code::EMERGENCY_STOP => (3, "Emergency stop"),
        code::UNSUPPORTED_COMMAND => (3, "Unsupported command"),
        code::INCORRECT_ARGUMENTS => (3, "Incorrect arguments"),
        code::ARGUMENT_OUT_OF_RANGE => (1, "Argument out of range"),
        code::ILLEGAL_COMMAND => (3, "Illegal command"),
        code::BAD_CONTEXT => (3, "Bad context"),
        code::BAD_ARGUMENT => (3, "Bad argument"),
        code::BAD_PROPERTY => (3, "Bad property"),
        code::ERROR_PROCESSING_METHOD => (3, "Error processing method"),
        code::DAEMON_DOES_NOT_EXIST => (2, "Daemon does not exist"),
        code::USE_CLEAR_ALL_ERRORS => (2, "Use ClearAllErrors to continue"),
        code::DAEMON_ALREADY_EXISTS => (2, "Daemon already exists"),
        code::NO_TOUCH => (2, "No touch"),
        code::SURFACE_NOT_FOUND => (2, "Surface not found"),
        code::VECTOR_HAS_NO_NORM => (2, "Vector has no norm"),
        code::TOOL_NOT_FOUND => (3, "Tool not found"),
        code::TOOL_NOT_DEFINED => (3, "Tool not defined"),
        code::PROBE_DOES_NOT_ALLOW => (3, "Type of probe does not allow this operation"),
        code::MACHINE_LIMIT => (3, "Machine limit encountered [Move Out Of Limits]"),
        code::COLLISION => (3, "Collision"),
        _ => unreachable!("code {code} is not in the simulator's table"),
    }
}

/// `tag ! Error(severity, code, "method", "text")`. The method field holds the failing method's name, as
/// spec 8.1 recommends.
pub fn error_line(tag: Tag, code: u16, method: &str) -> Response {
    let (severity, text) = describe(code);
    let method = WireString::new(method).unwrap_or_else(|_| WireString::new("Unknown").unwrap());
    let error = DeviceError::new(severity, code, method, WireString::new(text).unwrap())
        .expect("the table's severities and codes are in range");
    Response::new(tag, ResponseKind::Error(error)).expect("an error line is always valid")
}

/// Whether an error line needs ClearAllErrors (severity 2 and up, spec 8.1).
pub fn needs_clear(response: &Response) -> bool {
    matches!(response.kind(), ResponseKind::Error(e) if e.severity() >= 2)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formats_like_the_spec() {
        let line = error_line(Tag::Unsolicited, code::EMERGENCY_STOP, "EmergencyStop");
        assert_eq!(
            line.to_string(),
            "E0000 ! Error(3, 0500, \"EmergencyStop\", \"Emergency stop\")"
        );
        assert!(needs_clear(&line));
        let warning = error_line(Tag::Unsolicited, code::ARGUMENT_OUT_OF_RANGE, "SetProp");
        assert!(!needs_clear(&warning));
    }
}
