//! The PLY header: its format line, its elements with their counts, and their properties' types,
//! read up to `end_header`. Everything after it is the body (`body.rs`), laid out as the header
//! says.

use crate::error::{Error, Result, quote};
use std::collections::HashSet;
use std::path::Path;

/// How the body stores its values.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Format {
    Ascii,
    BinaryLittleEndian,
    BinaryBigEndian,
}

/// A value's type, by either of the names PLY files use (`uchar` or `uint8`, ...).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn named(name: &[u8]) -> Option<Scalar> {
        Some(match name {
            b"char" | b"int8" => Scalar::I8,
            b"uchar" | b"uint8" => Scalar::U8,
            b"short" | b"int16" => Scalar::I16,
            b"ushort" | b"uint16" => Scalar::U16,
            b"int" | b"int32" => Scalar::I32,
            b"uint" | b"uint32" => Scalar::U32,
            b"float" | b"float32" => Scalar::F32,
            b"double" | b"float64" => Scalar::F64,
            _ => return None,
        })
    }

    /// The type's name in a header (its older spelling).
    pub(super) fn name(self) -> &'static str {
        match self {
            Scalar::I8 => "char",
            Scalar::U8 => "uchar",
            Scalar::I16 => "short",
            Scalar::U16 => "ushort",
            Scalar::I32 => "int",
            Scalar::U32 => "uint",
            Scalar::F32 => "float",
            Scalar::F64 => "double",
        }
    }

    /// Bytes in a binary body.
    pub(super) fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }

    pub(super) fn is_integer(self) -> bool {
        self.integer_range().is_some()
    }

    /// The values an integer type holds (an ASCII body's integers are checked against them);
    /// `None` for the floating-point types.
    pub(super) fn integer_range(self) -> Option<(i64, i64)> {
        Some(match self {
            Scalar::I8 => (i8::MIN.into(), i8::MAX.into()),
            Scalar::U8 => (0, u8::MAX.into()),
            Scalar::I16 => (i16::MIN.into(), i16::MAX.into()),
            Scalar::U16 => (0, u16::MAX.into()),
            Scalar::I32 => (i32::MIN.into(), i32::MAX.into()),
            Scalar::U32 => (0, u32::MAX.into()),
            Scalar::F32 | Scalar::F64 => return None,
        })
    }
}

/// A property's type: one value, or a list of values preceded by their count.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Kind {
    Scalar(Scalar),
    List { count: Scalar, item: Scalar },
}

#[derive(Clone, Debug)]
pub(super) struct Property {
    pub(super) name: String,
    pub(super) kind: Kind,
}

#[derive(Clone, Debug)]
pub(super) struct Element {
    pub(super) name: String,
    pub(super) count: u64,
    pub(super) properties: Vec<Property>,
    /// The header line that declares it, for messages.
    pub(super) line: usize,
}

impl Element {
    /// The fewest bytes one instance takes in a body of `format`: in binary its values (a list at
    /// least its count), in ASCII a character and a separator per value (a list at least its count).
    pub(super) fn min_bytes(&self, format: Format) -> u64 {
        let size = |property: &Property| match (format, property.kind) {
            (Format::Ascii, _) => 2,
            (_, Kind::Scalar(scalar)) | (_, Kind::List { count: scalar, .. }) => scalar.size() as u64,
        };
        self.properties.iter().map(size).sum()
    }

    pub(super) fn property(&self, name: &str) -> Option<usize> {
        self.properties.iter().position(|property| property.name == name)
    }
}

#[derive(Debug)]
pub(super) struct Header {
    pub(super) format: Format,
    pub(super) elements: Vec<Element>,
    /// Where the body starts: just after the `end_header` line's end.
    pub(super) body_start: usize,
    /// The line the body starts on (for an ASCII body's messages).
    pub(super) body_line: usize,
}

/// Reads the header of the PLY file `bytes`; `file` names it in errors, which give the header line.
pub(super) fn parse_header(bytes: &[u8], file: &Path) -> Result<Header> {
    let mut format = None;
    let mut elements: Vec<Element> = Vec::new();
    // Names seen, to refuse repeats without comparing each new one with all before it (a header of
    // a hundred thousand properties is a few megabytes).
    let mut names: HashSet<(usize, String)> = HashSet::new();
    let mut start = 0;
    let mut number = 0;
    loop {
        number += 1;
        let Some(length) = bytes[start..].iter().position(|&b| b == b'\n') else {
            let message = if number == 1 { NOT_PLY } else { "the header has no end_header line" };
            return Err(Error::parse(file, number, message));
        };
        let line = &bytes[start..start + length];
        start += length + 1;
        let line = line.strip_suffix(b"\r").unwrap_or(line);
        if number == 1 {
            if line != b"ply" {
                return Err(Error::parse(file, 1, NOT_PLY));
            }
            continue;
        }
        let error = |message: String| Error::parse(file, number, message);
        let mut words = line.split(u8::is_ascii_whitespace).filter(|word| !word.is_empty());
        match words.next() {
            Some(b"end_header") => break,
            Some(b"comment" | b"obj_info") | None => {}
            Some(b"format") if format.is_some() => return Err(error("a second format line".to_string())),
            Some(b"format") => format = Some(parse_format(words.collect()).map_err(error)?),
            Some(b"element") => {
                let element = parse_element(words.collect(), number).map_err(error)?;
                if !names.insert((usize::MAX, element.name.clone())) {
                    return Err(error(format!("a second element {}", quote(&element.name))));
                }
                elements.push(element);
            }
            Some(b"property") => {
                let owner = elements.len();
                let Some(element) = elements.last_mut() else {
                    return Err(error("a property before any element".to_string()));
                };
                let property = parse_property(words.collect()).map_err(error)?;
                if !names.insert((owner, property.name.clone())) {
                    let (property, element) = (quote(&property.name), quote(&element.name));
                    return Err(error(format!("a second property {property} in element {element}")));
                }
                element.properties.push(property);
            }
            Some(keyword) => return Err(error(format!("unknown header keyword {}", quote(keyword)))),
        }
    }
    let Some(format) = format else {
        return Err(Error::parse(file, number, "the header ends without a format line"));
    };
    Ok(Header { format, elements, body_start: start, body_line: number + 1 })
}

const NOT_PLY: &str = "not a PLY file: its first line is not \"ply\"";

fn parse_format(words: Vec<&[u8]>) -> Result<Format, String> {
    let format = match words.first() {
        Some(&b"ascii") => Format::Ascii,
        Some(&b"binary_little_endian") => Format::BinaryLittleEndian,
        Some(&b"binary_big_endian") => Format::BinaryBigEndian,
        Some(other) => {
            return Err(format!(
                "unknown format {}: PLY bodies are ascii or binary_little_endian or binary_big_endian",
                quote(other)
            ));
        }
        None => return Err("format without a name".to_string()),
    };
    match words[1..] {
        [b"1.0" | b"1"] => Ok(format),
        [version] => Err(format!("PLY version {} is not supported: lumiere reads version 1.0", quote(version))),
        _ => Err("a format line is `format NAME 1.0`".to_string()),
    }
}

fn parse_element(words: Vec<&[u8]>, line: usize) -> Result<Element, String> {
    let [name, count] = words[..] else {
        return Err("an element line is `element NAME COUNT`".to_string());
    };
    let count = std::str::from_utf8(count)
        .ok()
        .and_then(|count| count.parse::<u64>().ok())
        .ok_or_else(|| format!("element count {} is not a whole number", quote(count)))?;
    Ok(Element { name: String::from_utf8_lossy(name).into_owned(), count, properties: Vec::new(), line })
}

fn parse_property(words: Vec<&[u8]>) -> Result<Property, String> {
    let scalar = |name: &[u8]| Scalar::named(name).ok_or_else(|| format!("unknown property type {}", quote(name)));
    let (kind, name) = match words[..] {
        [b"list", count, item, name] => {
            let (count, item) = (scalar(count)?, scalar(item)?);
            if !count.is_integer() {
                return Err(format!(
                    "list {} has a count of type {}, not an integer type",
                    quote(name),
                    quote(words[1])
                ));
            }
            (Kind::List { count, item }, name)
        }
        [b"list", ..] => return Err("a list property line is `property list COUNT_TYPE ITEM_TYPE NAME`".to_string()),
        [kind, name] => (Kind::Scalar(scalar(kind)?), name),
        _ => return Err("a property line is `property TYPE NAME`".to_string()),
    };
    Ok(Property { name: String::from_utf8_lossy(name).into_owned(), kind })
}
