//! The shape of a transaction's replies: what a client's control flow depends on (the markers, and for
//! data the names and kinds of the values), not the values themselves, which depend on the part on the
//! table.

use zeroset_drivers::wire::{Arg, Data, Response, ResponseKind};

/// One reply line, reduced to its shape.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Shape {
    Ack,
    Complete,
    /// `!`, with the code so that a table of known differences can name it.
    Error(u16),
    /// `#` with named values, e.g. `IsHomed(n)` or `X(n), IJK(nnn)`: `n` number, `s` string, `k` keyword,
    /// `e` event tag, `c` nested call.
    Calls(String),
    /// `#` with bare numbers (scan points): how many on the line.
    Numbers(usize),
    /// `#` of another kind (strings, vectors), with its number of items.
    Other(&'static str, usize),
}

impl Shape {
    pub fn of(response: &Response) -> Shape {
        match response.kind() {
            ResponseKind::Ack => Shape::Ack,
            ResponseKind::Complete => Shape::Complete,
            ResponseKind::Error(error) => Shape::Error(error.code()),
            ResponseKind::Data(Data::Calls(calls)) => Shape::Calls(
                calls
                    .iter()
                    .map(|call| {
                        let kinds: String = call.args.iter().map(kind).collect();
                        format!("{}({kinds})", call.name.as_str())
                    })
                    .collect::<Vec<_>>()
                    .join(","),
            ),
            ResponseKind::Data(Data::Numbers(numbers)) => Shape::Numbers(numbers.len()),
            ResponseKind::Data(Data::Strings(strings)) => Shape::Other("strings", strings.len()),
            ResponseKind::Data(Data::Vector(numbers)) => Shape::Other("vector", numbers.len()),
        }
    }
}

fn kind(arg: &Arg) -> char {
    match arg {
        Arg::Number(_) => 'n',
        Arg::String(_) => 's',
        Arg::Keyword(_) => 'k',
        Arg::EventTag(_) => 'e',
        Arg::Call(_) => 'c',
    }
}

/// How much of an error a rendering keeps.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ErrorDetail {
    /// `!`: the comparison with NIST, whose server uses its own codes at places (1008 for a target out
    /// of the volume, where 1.4.3 has 2500).
    Marker,
    /// `!0510`: the table of known differences, so that an entry names the error it explains.
    Code,
}

/// A transaction's replies as one line, e.g. `& # IsHomed(n) %` or `& #points/4 %`. A run of scan-data
/// lines becomes one `#points/W`, W the largest number dividing every line's count (the values per
/// point), since how the points are split into lines depends on the scan's length.
pub fn render(shapes: &[Shape], detail: ErrorDetail) -> String {
    let mut words: Vec<String> = Vec::new();
    let mut run: Option<usize> = None;
    for shape in shapes {
        if let Shape::Numbers(count) = shape {
            run = Some(run.map_or(*count, |width| gcd(width, *count)));
            continue;
        }
        if let Some(width) = run.take() {
            words.push(format!("#points/{width}"));
        }
        words.push(match (shape, detail) {
            (Shape::Ack, _) => "&".to_owned(),
            (Shape::Complete, _) => "%".to_owned(),
            (Shape::Error(_), ErrorDetail::Marker) => "!".to_owned(),
            (Shape::Error(code), ErrorDetail::Code) => format!("!{code:04}"),
            (Shape::Calls(calls), _) => format!("#{calls}"),
            (Shape::Other(what, count), _) => format!("#{what}/{count}"),
            (Shape::Numbers(_), _) => unreachable!("collected into the run above"),
        });
    }
    if let Some(width) = run {
        words.push(format!("#points/{width}"));
    }
    words.join(" ")
}

fn gcd(a: usize, b: usize) -> usize {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}
