//! NIST's I++ DME 1.4 test files (`shared/reference/ippdme-nist-1.4`, beside the checkout): the commands
//! of a .prg file and the transactions of the matching server log.
//!
//! A .prg file holds one message per entry, each followed by a line holding `\\`, and ends with two `:`
//! lines; a server log holds `<time> received: <command>` and `<time> Sent: <reply>` entries (and checker
//! notes, skipped).

use std::path::{Path, PathBuf};

use zeroset_drivers::wire::{Command, Response};

use super::shape::Shape;

pub fn nist_dir() -> PathBuf {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/reference/ippdme-nist-1.4");
    assert!(
        dir.join("README").is_file(),
        "NIST I++ DME test files not found at {}: the `shared` folder must sit beside the checkout",
        dir.display()
    );
    dir
}

fn read(path: &Path) -> String {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("reading {}: {e}", path.display()));
    String::from_utf8(bytes).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The commands of an executable .prg file, one line each.
pub fn program(path: &Path) -> Vec<Command> {
    let text = read(path);
    // Some files have blank lines after the end marker.
    let body = text
        .trim_end()
        .strip_suffix(":\r\n:")
        .unwrap_or_else(|| panic!("{} does not end with two `:` lines", path.display()));
    body.split("\\\\\r\n")
        .filter(|message| !message.is_empty())
        .map(|message| {
            let line = message
                .strip_suffix("\r\n")
                .unwrap_or_else(|| panic!("{}: `{message}` is not one line", path.display()));
            line.parse()
                .unwrap_or_else(|e| panic!("{}: `{line}`: {e}", path.display()))
        })
        .collect()
}

/// One command and the shapes of the replies that carry its tag, in order.
#[derive(Debug)]
pub struct Transaction {
    pub command: Command,
    pub replies: Vec<Shape>,
}

/// Files the replies of a command to it: a reply belongs to the latest command with its tag (a daemon's
/// reports come after its `%`; NIST files reuse tags now and then).
pub fn file_reply(transactions: &mut [Transaction], response: &Response) {
    let owner = transactions
        .iter_mut()
        .rev()
        .find(|t| t.command.tag() == response.tag())
        .unwrap_or_else(|| panic!("`{response}` answers no command sent"));
    owner.replies.push(Shape::of(response));
}

/// The transactions of a NIST server log.
pub fn server_log(path: &Path) -> Vec<Transaction> {
    let mut transactions = Vec::new();
    for entry in read(path).split("\r\n") {
        // Some entries end in CR CR LF: the logged line kept its own CR.
        let entry = entry.trim_end_matches('\r');
        let Some((_time, rest)) = entry.split_once(' ') else {
            continue;
        };
        if let Some(line) = rest.strip_prefix("received: ") {
            transactions.push(Transaction {
                command: line
                    .parse()
                    .unwrap_or_else(|e| panic!("{}: `{line}`: {e}", path.display())),
                replies: Vec::new(),
            });
        } else if let Some(line) = rest.strip_prefix("Sent: ") {
            let response: Response = line
                .parse()
                .unwrap_or_else(|e| panic!("{}: `{line}`: {e}", path.display()));
            file_reply(&mut transactions, &response);
        }
    }
    transactions
}
