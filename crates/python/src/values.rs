//! Python values to and from atelier's types, through serde: a Python dict (list, number,
//! string, bool, None) becomes a `serde_json::Value` ([`to_json`]) that serde deserialises into
//! the type the fabric or scenario file would give ([`deserialize`]), so the same checks run and
//! an error names the same field path as in a file (`tensile.warp.emt_percent`). Values come
//! back as Python objects ([`to_python`]) and positions as numpy arrays ([`array`]).

use numpy::{PyArray2, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
use serde::de::DeserializeOwned;
use serde_json::{Map, Number, Value};

use crate::errors::{Failure, join};

/// A Python value as JSON. `path` names it in errors. Accepts None, bool, int, float (finite),
/// str, dict with str keys, list, tuple, and anything with a `tolist()` (numpy arrays and
/// scalars). Another type is a `TypeError`; NaN or infinity a `ValueError` (not finite), both
/// naming the field.
pub fn to_json(obj: &Bound<'_, PyAny>, path: &str) -> Result<Value, Failure> {
    convert(obj, path, true)
}

fn convert(obj: &Bound<'_, PyAny>, path: &str, tolist: bool) -> Result<Value, Failure> {
    if obj.is_none() {
        return Ok(Value::Null);
    }
    if let Ok(b) = obj.cast::<PyBool>() {
        return Ok(Value::Bool(b.is_true()));
    }
    if obj.cast::<PyInt>().is_ok() {
        if let Ok(i) = obj.extract::<i64>() {
            return Ok(Value::Number(i.into()));
        }
        if let Ok(u) = obj.extract::<u64>() {
            return Ok(Value::Number(u.into()));
        }
        return Err(Failure::value(path, "integer too large"));
    }
    if let Ok(f) = obj.cast::<PyFloat>() {
        let v = f.value();
        return Number::from_f64(v).map(Value::Number).ok_or_else(|| {
            Failure::value(path, format!("not finite: {v} is not a finite number"))
        });
    }
    if let Ok(s) = obj.cast::<PyString>() {
        return Ok(Value::String(s.to_string()));
    }
    if let Ok(d) = obj.cast::<PyDict>() {
        let mut map = Map::new();
        for (k, v) in d.iter() {
            let key = k.cast::<PyString>().map(|s| s.to_string()).map_err(|_| {
                Failure::type_error(path, format!("a key must be a str, not {}", type_name(&k)))
            })?;
            let value = convert(&v, &join(path, &key), true)?;
            map.insert(key, value);
        }
        return Ok(Value::Object(map));
    }
    if obj.cast::<PyList>().is_ok() || obj.cast::<PyTuple>().is_ok() {
        let mut items = Vec::new();
        for (i, item) in obj
            .try_iter()
            .map_err(|e| Failure::type_error(path, e))?
            .enumerate()
        {
            let item = item.map_err(|e| Failure::type_error(path, e))?;
            items.push(convert(&item, &format!("{path}[{i}]"), true)?);
        }
        return Ok(Value::Array(items));
    }
    if tolist && obj.hasattr("tolist").unwrap_or(false) {
        // numpy arrays and scalars: their plain Python equivalent.
        let plain = obj
            .call_method0("tolist")
            .map_err(|e| Failure::type_error(path, e))?;
        return convert(&plain, path, false);
    }
    Err(Failure::type_error(
        path,
        format!(
            "a value of type `{}` cannot be given here (use numbers, strings, lists and dicts)",
            type_name(obj)
        ),
    ))
}

/// The Python type name of `obj`.
pub fn type_name(obj: &Bound<'_, PyAny>) -> String {
    obj.get_type()
        .name()
        .map_or_else(|_| "?".to_string(), |n| n.to_string())
}

/// Deserialise `value` into `T`, an error naming the field below `root`: a `TypeError` when a
/// value has the wrong type (serde's "invalid type"), a `ValueError` otherwise (an unknown or
/// missing field, an unknown variant, a value the type's own checks refuse — those travel as
/// `atelier_fabric::InvalidValue` messages, `[kind] field: message`, decoded here).
pub fn deserialize<T: DeserializeOwned>(value: Value, root: &str) -> Result<T, Failure> {
    serde_path_to_error::deserialize(value).map_err(|e| {
        let path = join(root, &field_path(e.path()));
        let message = e.inner().to_string();
        describe(&path, &message)
    })
}

/// The dotted field path of a serde path (enum variants left out, as in the files' errors).
fn field_path(path: &serde_path_to_error::Path) -> String {
    use serde_path_to_error::Segment;
    let mut out = String::new();
    for seg in path.iter() {
        match seg {
            Segment::Seq { index } => out.push_str(&format!("[{index}]")),
            Segment::Map { key } => out = join(&out, key),
            Segment::Enum { .. } | Segment::Unknown => {}
        }
    }
    out
}

/// The failure of a serde message at `path`.
fn describe(path: &str, message: &str) -> Failure {
    // An `InvalidValue` that travelled through serde: `[kind] field: message`.
    if let Some(rest) = message.strip_prefix('[')
        && let Some((kind, rest)) = rest.split_once("] ")
        && let Some((field, detail)) = rest.split_once(": ")
    {
        return Failure::value(&join(path, field), format!("{kind}: {detail}"));
    }
    if message.starts_with("invalid type") {
        return Failure::type_error(path, message);
    }
    if let Some(rest) = message.strip_prefix("missing field `")
        && let Some((name, _)) = rest.split_once('`')
    {
        return Failure::value(&join(path, name), message);
    }
    Failure::value(path, message)
}

/// A JSON value as a Python object (numbers that are whole and were written as integers stay
/// `int`).
pub fn to_python<'py>(py: Python<'py>, value: &Value) -> PyResult<Bound<'py, PyAny>> {
    Ok(match value {
        Value::Null => py.None().into_bound(py),
        Value::Bool(b) => PyBool::new(py, *b).to_owned().into_any(),
        Value::Number(n) => match (n.as_i64(), n.as_u64(), n.as_f64()) {
            (Some(i), _, _) => i.into_pyobject(py)?.into_any(),
            (_, Some(u), _) => u.into_pyobject(py)?.into_any(),
            (_, _, f) => f.unwrap_or(f64::NAN).into_pyobject(py)?.into_any(),
        },
        Value::String(s) => PyString::new(py, s).into_any(),
        Value::Array(items) => {
            let list = PyList::empty(py);
            for item in items {
                list.append(to_python(py, item)?)?;
            }
            list.into_any()
        }
        Value::Object(map) => {
            let dict = PyDict::new(py);
            for (k, v) in map {
                dict.set_item(k, to_python(py, v)?)?;
            }
            dict.into_any()
        }
    })
}

/// A serialisable value as a Python object (through JSON).
pub fn serialized<'py, T: serde::Serialize>(
    py: Python<'py>,
    value: &T,
) -> PyResult<Bound<'py, PyAny>> {
    let v = serde_json::to_value(value)
        .map_err(|e| crate::errors::AtelierError::new_err(format!("serialising a result: {e}")))?;
    to_python(py, &v)
}

/// Rows of `K` numbers as a numpy array of shape (rows, K), float64.
pub fn array<'py, const K: usize>(
    py: Python<'py>,
    rows: &[[f64; K]],
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let flat: Vec<f64> = rows.iter().flatten().copied().collect();
    numpy::PyArray1::from_vec(py, flat).reshape([rows.len(), K])
}

/// Rows of `K` indices as a numpy array of shape (rows, K), int64.
pub fn index_array<'py, const K: usize>(
    py: Python<'py>,
    rows: &[[u32; K]],
) -> PyResult<Bound<'py, PyArray2<i64>>> {
    let flat: Vec<i64> = rows.iter().flatten().map(|&i| i64::from(i)).collect();
    numpy::PyArray1::from_vec(py, flat).reshape([rows.len(), K])
}

/// `obj` as a JSON object (a dict), a `TypeError` naming `path` otherwise.
pub fn to_json_object(obj: &Bound<'_, PyAny>, path: &str) -> Result<Value, Failure> {
    match to_json(obj, path)? {
        v @ Value::Object(_) => Ok(v),
        _ => Err(Failure::type_error(
            path,
            format!("expected a dict, not `{}`", type_name(obj)),
        )),
    }
}
