//! Stage one: structs that mirror the file, every field optional.
//!
//! The structs themselves ([`crate::keys::RawScene`] and its tables) are defined with their
//! keys in [`crate::keys`]. Tables are typed (a `[simulation]` that is not a table is an error here), but every value
//! is kept as the [`toml::Value`] the user wrote: its type, range and cross-key rules are
//! checked in [`crate::validate`], which reports all problems at once with the value as
//! written. Unknown keys are not denied here but collected by `serde_ignored` (see
//! [`crate::parse`]), so that every misspelt key is reported, not only the first.
//!
//! Before deserializing, [`check_structure`] removes (and reports) every known table or array
//! of tables that has the wrong type, so that deserialization itself cannot fail and the rest
//! of the file is still checked.

use crate::catalog;
use crate::error::Problem;
use toml::{Table, Value};

/// Reports and removes each known table (`[simulation]`) or array of tables (`[[discs]]`)
/// whose value has another type; an item of an array of tables that is not a table becomes an
/// empty table (so later items keep their index). Leaves and unknown keys are left alone:
/// validation checks the types of leaves, and unknown keys are reported while deserializing.
/// Returns the key paths voided this way: "missing" problems under them are noise.
pub(crate) fn check_structure(doc: &mut Table, problems: &mut Vec<Problem>) -> Vec<String> {
    let mut voided = Vec::new();
    check_table(doc, "", problems, &mut voided);
    voided
}

/// `path` is the table's key path as written (`discs[1].oil`), `""` for the top level.
fn check_table(
    table: &mut Table,
    path: &str,
    problems: &mut Vec<Problem>,
    voided: &mut Vec<String>,
) {
    let mut wrong = Vec::new();
    for (key, value) in table.iter_mut() {
        let child = if path.is_empty() {
            key.clone()
        } else {
            format!("{path}.{key}")
        };
        let norm = catalog::normalize(&child);
        if catalog::is_leaf(&norm) || !catalog::is_known(&norm) {
            continue;
        }
        let section = norm.replace("[]", "");
        match value {
            Value::Array(items) if catalog::is_array(&norm) => {
                for (i, item) in items.iter_mut().enumerate() {
                    let item_path = format!("{child}[{i}]");
                    if let Value::Table(t) = item {
                        check_table(t, &item_path, problems, voided);
                    } else {
                        let rule = format!("must be a table (an [[{section}]] entry)");
                        problems.push(Problem::new(
                            &item_path,
                            Some(crate::schema::show(item)),
                            rule,
                        ));
                        *item = Value::Table(Table::new());
                        voided.push(item_path);
                    }
                }
            }
            Value::Table(t) if !catalog::is_array(&norm) => {
                check_table(t, &child, problems, voided)
            }
            _ => {
                let rule = if catalog::is_array(&norm) {
                    format!("must be an array of tables: write [[{section}]] entries")
                } else {
                    format!("must be a table: write [{section}]")
                };
                wrong.push((key.clone(), child, rule));
            }
        }
    }
    for (key, child, rule) in wrong {
        let value = table.remove(&key).map(|v| crate::schema::show(&v));
        problems.push(Problem::new(&child, value, rule));
        voided.push(child);
    }
}
