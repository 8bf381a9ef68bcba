//! One row of an `apt.dat`: its fields, read with errors that name the file, the line and the field.

use std::path::Path;

use crate::error::AirportError;
use crate::geodesy::LatLon;

/// A row: the row code is field 0.
pub(crate) struct Row<'a> {
    pub file: &'a Path,
    pub line: usize,
    pub code: u32,
    pub fields: Vec<&'a str>,
}

impl Row<'_> {
    pub fn error(
        &self,
        index: usize,
        field: &'static str,
        what: impl Into<String>,
    ) -> AirportError {
        AirportError::Field {
            file: self.file.to_path_buf(),
            line: self.line,
            code: self.code,
            index,
            field,
            what: what.into(),
        }
    }

    pub fn text(&self, index: usize, field: &'static str) -> Result<&str, AirportError> {
        self.fields.get(index).copied().ok_or_else(|| {
            self.error(
                index,
                field,
                format!("missing (the row has {} fields)", self.fields.len()),
            )
        })
    }

    /// The fields from `index` on, joined by single spaces (names with spaces); empty if none.
    pub fn rest(&self, index: usize) -> String {
        self.fields
            .get(index..)
            .map(|rest| rest.join(" "))
            .unwrap_or_default()
    }

    pub fn number(&self, index: usize, field: &'static str) -> Result<f64, AirportError> {
        let text = self.text(index, field)?;
        match text.parse::<f64>() {
            Ok(value) if value.is_finite() => Ok(value),
            _ => Err(self.error(index, field, format!("`{text}` is not a finite number"))),
        }
    }

    pub fn integer(&self, index: usize, field: &'static str) -> Result<u32, AirportError> {
        let text = self.text(index, field)?;
        text.parse::<u32>()
            .map_err(|_| self.error(index, field, format!("`{text}` is not a whole number >= 0")))
    }

    /// A latitude at `index` and the longitude after it, both in range.
    pub fn lat_lon(&self, index: usize) -> Result<LatLon, AirportError> {
        let lat = self.number(index, "latitude")?;
        if !(-90.0..=90.0).contains(&lat) {
            return Err(self.error(
                index,
                "latitude",
                format!("{lat} is outside -90..=90 degrees"),
            ));
        }
        let lon = self.number(index + 1, "longitude")?;
        if !(-180.0..=180.0).contains(&lon) {
            return Err(self.error(
                index + 1,
                "longitude",
                format!("{lon} is outside -180..=180 degrees"),
            ));
        }
        Ok(LatLon { lat, lon })
    }

    /// A positive length at `index`.
    pub fn positive(&self, index: usize, field: &'static str) -> Result<f64, AirportError> {
        let value = self.number(index, field)?;
        if value > 0.0 {
            Ok(value)
        } else {
            Err(self.error(index, field, format!("{value} is not > 0")))
        }
    }
}
