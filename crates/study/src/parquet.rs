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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::part::{CaseRecord, StudyHeader};
    use clutchpack_analysis::DiscStats;
    use parquet::file::reader::{FileReader, SerializedFileReader};
    use parquet::record::Field;

    /// Two cases, one failed: read back with the crate's own row reader (pyarrow's reading is
    /// the integration test's), the schema is the documented one (names, INT64/DOUBLE/UTF8,
    /// statistics and `error` optional) and every cell equals the CSV's.
    #[test]
    fn the_table_reads_back_with_its_schema_and_nulls() {
        let ok = CaseRecord {
            case: 0,
            design_point: 0,
            member: 0,
            values: vec![25e-6],
            discs: vec![DiscStats {
                max_positive_n: 812.5,
                max_negative_n: -901.25,
                impacts: 42,
                ..DiscStats::empty("d1")
            }],
            fatigue: vec![crate::part::CaseFatigue {
                damage_rate_per_h: 2e-6,
                life_h: Some(5e5),
                eq_load_range_n: 640.0,
            }],
            steps: 1000,
            rejected_steps: 3,
            simulated_s: 0.3,
            wall_s: 0.1,
            error: None,
        };
        let bad = CaseRecord {
            case: 1,
            member: 1,
            discs: Vec::new(),
            fatigue: Vec::new(),
            steps: 0,
            rejected_steps: 0,
            simulated_s: 0.0,
            error: Some("diverged, \"badly\"".into()),
            ..ok.clone()
        };
        let m = Merged {
            header: StudyHeader {
                name: "t".into(),
                hash: "h".into(),
                cases: 2,
                members: 2,
                columns: vec!["defaults.oil.film_thickness_m".into()],
                design_factors: 1,
                outputs: vec!["peak_abs_n".into(), "impacts".into()],
            },
            records: vec![ok, bad],
            discs: vec!["d1".into()],
        };
        let path =
            std::env::temp_dir().join(format!("clutchpack_study_{}.parquet", std::process::id()));
        write_results(&path, &m).unwrap();
        let r = SerializedFileReader::new(std::fs::File::open(&path).unwrap()).unwrap();
        let schema = r.metadata().file_metadata().schema_descr_ptr();
        let cols: Vec<(String, PhysicalType, bool)> = schema
            .columns()
            .iter()
            .map(|c| {
                (
                    c.name().to_string(),
                    c.physical_type(),
                    c.self_type().is_optional(),
                )
            })
            .collect();
        use PhysicalType::*;
        let want = [
            ("case", INT64, false),
            ("design_point", INT64, false),
            ("member", INT64, false),
            ("defaults.oil.film_thickness_m", DOUBLE, false),
            ("d1.peak_abs_n", DOUBLE, true),
            ("d1.impacts", INT64, true),
            ("steps", INT64, false),
            ("rejected_steps", INT64, false),
            ("simulated_s", DOUBLE, false),
            ("error", BYTE_ARRAY, true),
        ];
        assert_eq!(cols.len(), want.len());
        for ((n, t, o), (wn, wt, wo)) in cols.iter().zip(want) {
            assert_eq!((n.as_str(), *t, *o), (wn, wt, wo));
        }
        let rows: Vec<Vec<Field>> = r
            .get_row_iter(None)
            .unwrap()
            .map(|row| {
                row.unwrap()
                    .get_column_iter()
                    .map(|(_, f)| f.clone())
                    .collect()
            })
            .collect();
        assert_eq!(rows.len(), 2);
        assert_eq!(rows[0][4], Field::Double(901.25));
        assert_eq!(rows[0][5], Field::Long(42));
        assert_eq!(rows[0][9], Field::Null);
        assert_eq!(rows[1][4], Field::Null);
        assert_eq!(rows[1][5], Field::Null);
        assert_eq!(rows[1][9], Field::Str("diverged, \"badly\"".into()));
        assert!(m
            .csv()
            .lines()
            .nth(2)
            .unwrap()
            .ends_with(",,,0,0,0,\"diverged, \"\"badly\"\"\""));
        let _ = std::fs::remove_file(path);
    }
}
