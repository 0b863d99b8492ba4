//! A PLY body read value by value, in the order the header lays it out: whitespace-separated
//! numbers in an ASCII body, fixed-size values of either byte order in a binary one. Reading
//! never goes past the end: a short body is an error that says where it ends.

use super::header::{Element, Format, Header, Kind, Scalar};
use crate::error::{Error, quote, shown_path};
use std::path::Path;

pub(super) struct Body<'a> {
    bytes: &'a [u8],
    format: Format,
    at: usize,
    /// Where the last value read (or tried) starts, and its line in an ASCII body: messages name it.
    last: usize,
    line: usize,
    last_line: usize,
}

/// A value as its type holds it.
enum Value {
    Integer(i64),
    Real(f64),
}

impl<'a> Body<'a> {
    /// The body of the file `bytes`, whose header is `header`.
    pub(super) fn new(bytes: &'a [u8], header: &Header) -> Self {
        let (at, line) = (header.body_start, header.body_line);
        Body { bytes, format: header.format, at, last: at, line, last_line: line }
    }

    /// The bytes left.
    pub(super) fn remaining(&self) -> usize {
        self.bytes.len() - self.at
    }

    /// An error about the value last read, with its place: the line in an ASCII body, the byte's
    /// offset in a binary one.
    pub(super) fn error(&self, file: &Path, message: String) -> Error {
        match self.format {
            Format::Ascii => Error::parse(file, self.last_line, message),
            _ => Error::invalid(format!("{}: byte {}: {message}", shown_path(file), self.last)),
        }
    }

    /// A value of type `scalar`, as a real number.
    pub(super) fn real(&mut self, scalar: Scalar) -> Result<f64, String> {
        Ok(match self.value(scalar)? {
            Value::Integer(value) => value as f64,
            Value::Real(value) => value,
        })
    }

    /// A value of the integer type `scalar`.
    pub(super) fn integer(&mut self, scalar: Scalar) -> Result<i64, String> {
        match self.value(scalar)? {
            Value::Integer(value) => Ok(value),
            Value::Real(_) => Err(format!("a value of type {} where an integer was expected", scalar.name())),
        }
    }

    /// Passes over one value of a property of `kind`.
    pub(super) fn skip(&mut self, kind: Kind) -> Result<(), String> {
        match kind {
            Kind::Scalar(scalar) => self.value(scalar).map(drop),
            Kind::List { count, item } => {
                let count = self.list_count(count)?;
                match self.format {
                    Format::Ascii => (0..count).try_for_each(|_| self.value(item).map(drop)),
                    _ => self.advance(count.saturating_mul(item.size() as u64)),
                }
            }
        }
    }

    /// Passes over every instance of `element`: in a binary body whose element has no lists,
    /// in one step.
    pub(super) fn skip_element(&mut self, element: &Element) -> Result<(), String> {
        if element.properties.is_empty() {
            return Ok(());
        }
        let fixed = element.properties.iter().all(|property| matches!(property.kind, Kind::Scalar(_)));
        if fixed && self.format != Format::Ascii {
            return self.advance(element.count.saturating_mul(element.min_bytes(self.format)));
        }
        for _ in 0..element.count {
            for property in &element.properties {
                self.skip(property.kind)?;
            }
        }
        Ok(())
    }

    /// A list's count, which may not be negative.
    pub(super) fn list_count(&mut self, scalar: Scalar) -> Result<u64, String> {
        let count = self.integer(scalar)?;
        u64::try_from(count).map_err(|_| format!("a list of {count} values"))
    }

    /// What follows the last element, if anything but an ASCII body's trailing whitespace:
    /// `(bytes, line)` for a warning.
    pub(super) fn trailing(&self) -> Option<(usize, usize)> {
        let rest = &self.bytes[self.at..];
        match self.format {
            Format::Ascii if rest.iter().all(u8::is_ascii_whitespace) => None,
            Format::Ascii => {
                let blank = rest.iter().position(|b| !b.is_ascii_whitespace()).unwrap_or(0);
                Some((rest.len() - blank, self.line + rest[..blank].iter().filter(|&&b| b == b'\n').count()))
            }
            _ if rest.is_empty() => None,
            _ => Some((rest.len(), 0)),
        }
    }

    fn value(&mut self, scalar: Scalar) -> Result<Value, String> {
        match self.format {
            Format::Ascii => self.text_value(scalar),
            Format::BinaryLittleEndian => self.binary_value(scalar, false),
            Format::BinaryBigEndian => self.binary_value(scalar, true),
        }
    }

    fn text_value(&mut self, scalar: Scalar) -> Result<Value, String> {
        let token = self.token()?;
        let text = std::str::from_utf8(token).unwrap_or_default();
        let Some((low, high)) = scalar.integer_range() else {
            return text.parse().map(Value::Real).map_err(|_| format!("malformed number {}", quote(token)));
        };
        match text.parse::<i64>() {
            Ok(value) if (low..=high).contains(&value) => Ok(Value::Integer(value)),
            Ok(_) => Err(format!("{} is out of the range of its type, {}", quote(token), scalar.name())),
            Err(_) => Err(format!("malformed integer {}", quote(token))),
        }
    }

    /// The next whitespace-separated token of an ASCII body.
    fn token(&mut self) -> Result<&'a [u8], String> {
        while let Some(&byte) = self.bytes.get(self.at).filter(|b| b.is_ascii_whitespace()) {
            self.line += usize::from(byte == b'\n');
            self.at += 1;
        }
        (self.last, self.last_line) = (self.at, self.line);
        let length = self.bytes[self.at..].iter().position(u8::is_ascii_whitespace).unwrap_or(self.remaining());
        if length == 0 {
            return Err(SHORT.to_string());
        }
        self.at += length;
        Ok(&self.bytes[self.at - length..self.at])
    }

    fn binary_value(&mut self, scalar: Scalar, big_endian: bool) -> Result<Value, String> {
        self.last = self.at;
        let size = scalar.size();
        let Some(bytes) = self.bytes.get(self.at..self.at + size) else {
            return Err(SHORT.to_string());
        };
        self.at += size;
        let mut raw = [0u8; 8];
        raw[..size].copy_from_slice(bytes);
        if big_endian {
            raw[..size].reverse();
        }
        // `raw` now holds the value little-endian, in its first `size` bytes.
        let [b0, b1, b2, b3, ..] = raw;
        Ok(match scalar {
            Scalar::I8 => Value::Integer(i8::from_le_bytes([b0]).into()),
            Scalar::U8 => Value::Integer(b0.into()),
            Scalar::I16 => Value::Integer(i16::from_le_bytes([b0, b1]).into()),
            Scalar::U16 => Value::Integer(u16::from_le_bytes([b0, b1]).into()),
            Scalar::I32 => Value::Integer(i32::from_le_bytes([b0, b1, b2, b3]).into()),
            Scalar::U32 => Value::Integer(u32::from_le_bytes([b0, b1, b2, b3]).into()),
            Scalar::F32 => Value::Real(f32::from_le_bytes([b0, b1, b2, b3]).into()),
            Scalar::F64 => Value::Real(f64::from_le_bytes(raw)),
        })
    }

    /// Passes over `bytes` bytes of a binary body.
    fn advance(&mut self, bytes: u64) -> Result<(), String> {
        self.last = self.at;
        match usize::try_from(bytes) {
            Ok(bytes) if bytes <= self.remaining() => {
                self.at += bytes;
                Ok(())
            }
            _ => Err(SHORT.to_string()),
        }
    }
}

pub(super) const SHORT: &str = "the file ends before the values its header declares";
