//! The results table as Parquet (what pandas, polars and DuckDB read), with the `parquet`
//! crate's column writers: no Arrow, no compression codecs (the table is small next to the
//! runs that made it; dictionary encoding is on).

use crate::merge::{Cell, Kind, Merged};
use parquet::basic::{LogicalType, Repetition, Type as PhysicalType};
use parquet::data_type::{ByteArray, ByteArrayType, DoubleType, Int64Type};
use parquet::file::properties::WriterProperties;
use parquet::file::writer::SerializedFileWriter;
use parquet::schema::types::Type;
use std::path::Path;
use std::sync::Arc;

/// Why the Parquet file could not be written.
#[derive(Debug, thiserror::Error)]
#[error("{}: writing Parquet: {reason}", path.display())]
pub struct ParquetError {
    /// The file.
    pub path: std::path::PathBuf,
    /// Why.
    pub reason: String,
}

/// Writes the results table of `merged` to `path` (one row group; the columns of
/// [`crate::merge`]'s module doc: INT64 and DOUBLE columns required unless they can be null,
/// the statistics and `error` optional).
pub fn write_results(path: &Path, merged: &Merged) -> Result<(), ParquetError> {
    let err = |e: &dyn std::fmt::Display| ParquetError {
        path: path.into(),
        reason: e.to_string(),
    };
    let schema = merged.schema();
    let rows = merged.rows();
    let nullable: Vec<bool> = (0..schema.len())
        .map(|c| {
            schema[c].1 == Kind::Text
                || rows.iter().any(|r| r[c] == Cell::Null)
                || is_stat(&schema[c].0, merged)
        })
        .collect();
    let fields = schema
        .iter()
        .zip(&nullable)
        .map(|((name, kind), &null)| {
            let (phys, logical) = match kind {
                Kind::Int => (PhysicalType::INT64, None),
                Kind::Float => (PhysicalType::DOUBLE, None),
                Kind::Text => (PhysicalType::BYTE_ARRAY, Some(LogicalType::String)),
            };
            Type::primitive_type_builder(name, phys)
                .with_repetition(if null {
                    Repetition::OPTIONAL
                } else {
                    Repetition::REQUIRED
                })
                .with_logical_type(logical)
                .build()
                .map(Arc::new)
        })
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| err(&e))?;
    let root = Type::group_type_builder("clutchpack_study")
        .with_fields(fields)
        .build()
        .map_err(|e| err(&e))?;
    let props = Arc::new(
        WriterProperties::builder()
            .set_created_by(format!("clutchpack {}", env!("CARGO_PKG_VERSION")))
            .build(),
    );
    let file = std::fs::File::create(path).map_err(|e| err(&e))?;
    let mut w = SerializedFileWriter::new(file, Arc::new(root), props).map_err(|e| err(&e))?;
    let mut rg = w.next_row_group().map_err(|e| err(&e))?;
    let mut c = 0;
    while let Some(mut col) = rg.next_column().map_err(|e| err(&e))? {
        let cells = rows.iter().map(|r| &r[c]);
        let defs: Vec<i16> = cells.clone().map(|x| i16::from(*x != Cell::Null)).collect();
        let defs = nullable[c].then_some(defs.as_slice());
        let written = match schema[c].1 {
            Kind::Int => {
                let v: Vec<i64> = cells
                    .filter_map(|x| match x {
                        Cell::Int(i) => Some(*i),
                        _ => None,
                    })
                    .collect();
                col.typed::<Int64Type>().write_batch(&v, defs, None)
            }
            Kind::Float => {
                let v: Vec<f64> = cells
                    .filter_map(|x| match x {
                        Cell::Float(f) => Some(*f),
                        _ => None,
                    })
                    .collect();
                col.typed::<DoubleType>().write_batch(&v, defs, None)
            }
            Kind::Text => {
                let v: Vec<ByteArray> = cells
                    .filter_map(|x| match x {
                        Cell::Text(t) => Some(ByteArray::from(t.as_str())),
                        _ => None,
                    })
                    .collect();
                col.typed::<ByteArrayType>().write_batch(&v, defs, None)
            }
        };
        written.map_err(|e| err(&e))?;
        col.close().map_err(|e| err(&e))?;
        c += 1;
    }
    rg.close().map_err(|e| err(&e))?;
    w.close().map_err(|e| err(&e))?;
    Ok(())
}

/// Per-disc statistic columns are always nullable (a failed case has none), so that the
/// schema does not depend on whether a case failed.
fn is_stat(name: &str, m: &Merged) -> bool {
    m.discs
        .iter()
        .any(|d| name.starts_with(d.as_str()) && name[d.len()..].starts_with('.'))
}
