//! Writing the elements QIF is made of: text and decimal elements, id-bearing elements, counted lists and
//! id references.

use std::io;

use quick_xml::escape::partial_escape;
use quick_xml::events::BytesText;
use quick_xml::writer::ElementWriter;
use quick_xml::Writer;

pub(super) type Xml = Writer<Vec<u8>>;

/// Numbers as QIF lists and decimals want them: Rust's shortest representation that reads back to the same f64,
/// never in exponent notation (which xs:decimal forbids).
pub(super) fn numbers(values: impl Iterator<Item = f64>) -> String {
    values
        .map(|value| value.to_string())
        .collect::<Vec<_>>()
        .join(" ")
}

pub(super) fn decimal(xml: &mut Xml, name: &str, value: f64) -> io::Result<()> {
    text(xml, name, &value.to_string())
}

/// `<name>value</name>`, escaping only what XML requires in text (`<`, `>`, `&`), so prose stays readable.
pub(super) fn text(xml: &mut Xml, name: &str, value: &str) -> io::Result<()> {
    xml.create_element(name)
        .write_text_content(BytesText::from_escaped(partial_escape(value)))?;
    Ok(())
}

pub(super) fn reference(xml: &mut Xml, name: &str, id: u32) -> io::Result<()> {
    text(xml, name, &id.to_string())
}

/// A QIF id array: `<name n="k"><Id>..</Id>...</name>`.
pub(super) fn references(xml: &mut Xml, name: &str, targets: &[u32]) -> io::Result<()> {
    counted(xml, name, targets.len()).write_inner_content(|xml| {
        for &target in targets {
            reference(xml, "Id", target)?;
        }
        Ok(())
    })?;
    Ok(())
}

pub(super) fn with_id<'a>(xml: &'a mut Xml, name: &'a str, id: u32) -> ElementWriter<'a, Vec<u8>> {
    xml.create_element(name)
        .with_attribute(("id", id.to_string().as_str()))
}

/// A QIF list element with its `n` (number of entries) attribute.
pub(super) fn counted<'a>(xml: &'a mut Xml, name: &'a str, n: usize) -> ElementWriter<'a, Vec<u8>> {
    xml.create_element(name)
        .with_attribute(("n", n.to_string().as_str()))
}
