//! Arrow tables from recorded buffers, with the one schema of [`crate::record`].
//!
//! Numeric buffers move into Arrow arrays without copying.

use std::collections::HashMap;
use std::sync::Arc;

use arrow_array::types::UInt32Type;
use arrow_array::{
    ArrayRef, DictionaryArray, Float64Array, RecordBatch, StringArray, UInt32Array, UInt64Array,
};
use arrow_schema::{ArrowError, DataType, Field, Schema};

use crate::record::{ColumnData, ColumnKind, Dictionary, Recording, TableBuffer, TableDef};

/// Arrow schema of a table, with `unit` and `description` in each field's
/// metadata and, in the schema's (which Parquet writers keep as the file's
/// key–value metadata, where DuckDB's `parquet_kv_metadata` and polars read
/// it), the table's `ballcage.table` and `ballcage.row` and the JSON objects
/// `ballcage.units` and `ballcage.descriptions` (column → text), besides
/// `metadata`.
pub fn schema(table: &TableDef, mut metadata: HashMap<String, String>) -> Schema {
    metadata.insert("ballcage.table".to_string(), table.name.to_string());
    metadata.insert("ballcage.row".to_string(), table.row.to_string());
    metadata.insert(
        "ballcage.units".to_string(),
        json_object(table.columns.iter().map(|c| (c.name, c.unit))),
    );
    metadata.insert(
        "ballcage.descriptions".to_string(),
        json_object(table.columns.iter().map(|c| (c.name, c.description))),
    );
    let fields: Vec<Field> = table
        .columns
        .iter()
        .map(|c| {
            let dt = match c.kind {
                ColumnKind::U64 => DataType::UInt64,
                ColumnKind::U32 => DataType::UInt32,
                ColumnKind::F64 => DataType::Float64,
                ColumnKind::OptU32 => DataType::UInt32,
                ColumnKind::OptF64 => DataType::Float64,
                ColumnKind::Name(_) | ColumnKind::OptName(_) => {
                    DataType::Dictionary(Box::new(DataType::UInt32), Box::new(DataType::Utf8))
                }
            };
            let mut md = HashMap::new();
            md.insert("unit".to_string(), c.unit.to_string());
            md.insert("description".to_string(), c.description.to_string());
            let nullable = matches!(
                c.kind,
                ColumnKind::OptU32 | ColumnKind::OptF64 | ColumnKind::OptName(_)
            );
            Field::new(c.name, dt, nullable).with_metadata(md)
        })
        .collect();
    Schema::new_with_metadata(fields, metadata)
}

/// A JSON object of string values, in the order given.
fn json_object<'a>(pairs: impl Iterator<Item = (&'a str, &'a str)>) -> String {
    let body: Vec<String> = pairs
        .map(|(k, v)| format!("{}: {}", json_string(k), json_string(v)))
        .collect();
    format!("{{{}}}", body.join(", "))
}

/// A JSON string literal.
fn json_string(s: &str) -> String {
    let mut out = String::with_capacity(s.len() + 2);
    out.push('"');
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            c if (c as u32) < 0x20 => out.push_str(&format!("\\u{:04x}", c as u32)),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// One record batch per recorded table, with the run metadata on each schema.
pub fn record_batches(rec: Recording) -> Result<Vec<(&'static TableDef, RecordBatch)>, ArrowError> {
    let metadata: HashMap<String, String> = rec.metadata.iter().cloned().collect();
    let dict_values =
        |names: &[String]| -> ArrayRef { Arc::new(StringArray::from_iter_values(names.iter())) };
    let bodies = dict_values(&rec.body_names);
    let pairs = dict_values(&rec.pair_names);
    let parts: ArrayRef = Arc::new(StringArray::from_iter_values(rec.part_labels.iter()));
    let labels = |dict: Dictionary| -> ArrayRef {
        match dict {
            Dictionary::Bodies => bodies.clone(),
            Dictionary::Pairs => pairs.clone(),
            Dictionary::Parts => parts.clone(),
            Dictionary::Labels(labels) => Arc::new(StringArray::from_iter_values(labels.iter())),
        }
    };
    let mut out = Vec::with_capacity(rec.tables.len());
    for TableBuffer { def, data, .. } in rec.tables {
        let schema = Arc::new(schema(def, metadata.clone()));
        let arrays = def
            .columns
            .iter()
            .zip(data)
            .map(|(c, d)| -> Result<ArrayRef, ArrowError> {
                Ok(match (c.kind, d) {
                    (ColumnKind::U64, ColumnData::U64(v)) => Arc::new(UInt64Array::from(v)),
                    (ColumnKind::U32, ColumnData::U32(v)) => Arc::new(UInt32Array::from(v)),
                    (ColumnKind::F64, ColumnData::F64(v)) => Arc::new(Float64Array::from(v)),
                    (ColumnKind::OptU32, ColumnData::OptU32(v)) => Arc::new(UInt32Array::from(v)),
                    (ColumnKind::OptF64, ColumnData::OptF64(v)) => Arc::new(Float64Array::from(v)),
                    (ColumnKind::Name(dict), ColumnData::U32(v)) => {
                        Arc::new(DictionaryArray::<UInt32Type>::try_new(
                            UInt32Array::from(v),
                            labels(dict),
                        )?)
                    }
                    (ColumnKind::OptName(dict), ColumnData::OptU32(v)) => Arc::new(
                        DictionaryArray::<UInt32Type>::try_new(UInt32Array::from(v), labels(dict))?,
                    ),
                    (k, _) => {
                        return Err(ArrowError::SchemaError(format!(
                            "column {} ({k:?}) has mismatched data",
                            c.name
                        )));
                    }
                })
            })
            .collect::<Result<Vec<_>, _>>()?;
        out.push((def, RecordBatch::try_new(schema, arrays)?));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn json_strings_escape_quotes_backslashes_and_control_characters() {
        assert_eq!(json_string(r#"a "b" \ c"#), r#""a \"b\" \\ c""#);
        assert_eq!(json_string("x\ny"), r#""x\u000ay""#);
        assert_eq!(
            json_object([("t", "s"), ("f", "N*m")].into_iter()),
            r#"{"t": "s", "f": "N*m"}"#
        );
    }
}
