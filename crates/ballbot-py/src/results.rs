//! The one path from a Rust result to a `ballbot._results` class.
//!
//! A result (or the binding's view of it, when Python's form is not the Rust type's: columns
//! rather than rows, a status's fields lifted to the top) is `serde::Serialize`.
//! [`build`] turns it into plain Python objects with `pythonize` (dicts, lists, `float` for
//! every `f64`, NaN and infinities included, `int`, `str`, `None`) and hands them to
//! `ballbot._results._build`, which makes the class and converts each field by its annotation
//! in one place: numpy arrays from the [`Array`] form, nested result classes, enums from their
//! canonical names (`as_str`/`label`), `Failure` from its parts ([`FailureParts`]).
//!
//! The rule for numpy arrays: a field that Python sees as an array serializes as an
//! [`Array`] (`{"dtype", "shape", "data"}`, the values' native-endian bytes). A time series
//! kept as rows in Rust (`Vec<Sample>`) becomes its columns through [`Columns`]: each field of
//! the row type is one array, `(n,)` for a scalar, `(n, k)` for a `[_; k]`, named as the
//! field. `pythonize` makes a fixed-size array (`[T; N]`, a serde tuple) a Python `tuple` and
//! a `Vec` a `list`; `_build` turns either into what the annotation says (`list[float]`,
//! `tuple[bool, bool, bool]`), but inside a field typed `dict[str, Any]` a `[T; N]` would stay
//! a tuple; an [`Array`] inside such a field (a PIPTB trial's `series`) is still an array.
//! [`build_objects`] is the same path for a view whose fields are Python objects already (a
//! rollout's arrays, made from the Rust buffers without a copy).
//!
//! The classes are generated from the views' schemas ([`crate::mirror`], [`PyResultClass`]):
//! the view's schema name is the class's name, so the two cannot disagree.

use pyo3::BoundObject;
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use schemars::{JsonSchema, Schema, SchemaGenerator, json_schema};
use serde::ser::{self, Impossible, SerializeMap, SerializeStruct};
use serde::{Serialize, Serializer};
use serde_json::{Map, Value, json};
use std::borrow::Cow;
use std::fmt;

static RESULTS_MODULE: PyOnceLock<Py<PyModule>> = PyOnceLock::new();

fn results_module(py: Python<'_>) -> PyResult<&Bound<'_, PyModule>> {
    Ok(RESULTS_MODULE
        .get_or_try_init(py, || py.import("ballbot._results").map(|m| m.unbind()))?
        .bind(py))
}

/// A Rust result (or the binding's view of it) that has a generated class in
/// `ballbot._results`: its schema's name (`#[schemars(rename = "...")]`) is the class's name,
/// and `scripts/gen-python-mirror.py` writes the class from its schema in the mirror's bundle
/// ([`crate::mirror`]). Implemented by the bundle's list only, so that [`build`] and
/// [`build_objects`] take no type whose class was not generated.
pub trait PyResultClass: JsonSchema {}

/// An instance of the generated class of `T` (in `ballbot._results`) from `value`, through
/// `pythonize` and `ballbot._results._build` (see the module's doc): the fields of `value`'s
/// serde form are the class's fields, by name.
pub fn build<'py, T: PyResultClass + Serialize>(
    py: Python<'py>,
    value: &T,
) -> PyResult<Bound<'py, PyAny>> {
    let data = pythonize::pythonize(py, value)?;
    build_from(py, T::schema_name(), data)
}

/// [`build`] for a view whose fields are Python objects already (numpy arrays made from the
/// Rust buffers without a copy, native classes): `#[derive(IntoPyObject)]` makes the dict of
/// them, `_build` takes such fields as they are.
pub fn build_objects<'py, T>(py: Python<'py>, value: T) -> PyResult<Bound<'py, PyAny>>
where
    T: PyResultClass + IntoPyObject<'py>,
    PyErr: From<T::Error>,
{
    let data = value.into_pyobject(py)?.into_any().into_bound();
    build_from(py, T::schema_name(), data)
}

fn build_from<'py>(
    py: Python<'py>,
    class_name: Cow<'static, str>,
    data: Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyAny>> {
    results_module(py)?
        .getattr("_build")?
        .call1((class_name, data))
}

/// A numpy dtype the conversion carries: `f8`, `?` (bool) or `i1`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Dtype {
    F64,
    Bool,
    I8,
}

impl Dtype {
    fn as_str(self) -> &'static str {
        match self {
            Self::F64 => "f8",
            Self::Bool => "?",
            Self::I8 => "i1",
        }
    }
}

/// An element of an [`Array`]: its dtype and native-endian bytes.
pub(crate) trait Element: Copy {
    const DTYPE: Dtype;
    fn put(self, out: &mut Vec<u8>);
}

impl Element for f64 {
    const DTYPE: Dtype = Dtype::F64;
    fn put(self, out: &mut Vec<u8>) {
        out.extend_from_slice(&self.to_ne_bytes());
    }
}

impl Element for bool {
    const DTYPE: Dtype = Dtype::Bool;
    fn put(self, out: &mut Vec<u8>) {
        out.push(u8::from(self));
    }
}

impl Element for i8 {
    const DTYPE: Dtype = Dtype::I8;
    fn put(self, out: &mut Vec<u8>) {
        out.extend_from_slice(&self.to_ne_bytes());
    }
}

/// A numpy array as the conversion carries it: serialized as `{"dtype": "f8", "shape": [n,
/// k], "data": bytes}`; `ballbot._results._build` makes an owned, writable, C-contiguous numpy
/// array of it.
#[derive(Clone, Debug, PartialEq)]
pub struct Array {
    dtype: Dtype,
    shape: Vec<usize>,
    data: Vec<u8>,
}

impl Array {
    /// A 1-D array, `(n,)`, of `values`.
    pub(crate) fn column<T: Element>(values: impl IntoIterator<Item = T>) -> Self {
        let mut data = Vec::new();
        let mut n = 0;
        for v in values {
            v.put(&mut data);
            n += 1;
        }
        Self {
            dtype: T::DTYPE,
            shape: vec![n],
            data,
        }
    }
}

/// Bytes serialized as bytes (Python `bytes`), not as a sequence of integers.
struct Bytes<'a>(&'a [u8]);

impl Serialize for Bytes<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_bytes(self.0)
    }
}

impl Serialize for Array {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut st = s.serialize_struct("Array", 3)?;
        st.serialize_field("dtype", self.dtype.as_str())?;
        st.serialize_field("shape", &self.shape)?;
        st.serialize_field("data", &Bytes(&self.data))?;
        st.end()
    }
}

/// In the mirror's schema, an array (`x-python-type`); its dtype and shape are the field's
/// (`#[schemars(extend("x-python-dtype" = "f8", "x-python-shape" = [3]))]`).
impl JsonSchema for Array {
    fn schema_name() -> Cow<'static, str> {
        "Array".into()
    }

    fn inline_schema() -> bool {
        true
    }

    fn json_schema(_: &mut SchemaGenerator) -> Schema {
        json_schema!({ "type": "object", "x-python-type": "numpy.ndarray" })
    }
}

/// A failure's parts, the form `Failure._from_parts` takes (and pickling uses): the kind's
/// canonical name, the wheel index, the tilt, the time.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, JsonSchema)]
#[schemars(rename = "Failure", extend("x-python-type" = "ballbot._core.Failure"))]
pub struct FailureParts {
    /// `FailureKind::as_str`.
    pub kind: &'static str,
    /// The wheel (0-based) for slip, lift-off and a driver trip.
    pub wheel: Option<usize>,
    /// The tilt for a tilt failure (rad).
    pub tilt_rad: Option<f64>,
    /// When it was detected (s).
    pub time_secs: f64,
}

impl From<ballbot_sim::world::Failure> for FailureParts {
    fn from(f: ballbot_sim::world::Failure) -> Self {
        Self {
            kind: f.kind.as_str(),
            wheel: f.kind.wheel(),
            tilt_rad: f.kind.tilt_rad(),
            time_secs: f.time_secs,
        }
    }
}

/// The rows of a time series as numpy columns, one [`Array`] per field of `T`, keyed by the
/// field's serde name: `(n,)` for an `f64`, `bool` or `i8` field, `(n, k)` for a `[_; k]` one.
/// A view's field `#[serde(flatten)] columns: Columns<'a, Sample>` puts them beside the view's
/// other fields. `T::default()` gives the columns' names and widths when there are no rows.
pub struct Columns<'a, T>(pub &'a [T]);

impl<T: Serialize + Default> Serialize for Columns<'_, T> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut table = Table {
            columns: Vec::new(),
            learning: true,
            next: 0,
        };
        T::default()
            .serialize(RowSerializer(&mut table))
            .map_err(ser::Error::custom)?;
        for column in &mut table.columns {
            column.data.clear();
        }
        table.learning = false;
        for row in self.0 {
            table.next = 0;
            row.serialize(RowSerializer(&mut table))
                .map_err(ser::Error::custom)?;
        }
        let n = self.0.len();
        let mut map = s.serialize_map(Some(table.columns.len()))?;
        for column in table.columns {
            let shape = match column.width {
                None => vec![n],
                Some(k) => vec![n, k],
            };
            let array = Array {
                dtype: column.dtype,
                shape,
                data: column.data,
            };
            map.serialize_entry(column.name, &array)?;
        }
        map.end()
    }
}

/// In the mirror's schema, one array per field of the row type `T`, described by the field's
/// doc comment: dtype `f8`, `?` or `i1`, shape `["n"]` or `["n", k]`.
impl<T: JsonSchema> JsonSchema for Columns<'_, T> {
    fn schema_name() -> Cow<'static, str> {
        format!("Columns_of_{}", T::schema_name()).into()
    }

    fn inline_schema() -> bool {
        true
    }

    fn json_schema(generator: &mut SchemaGenerator) -> Schema {
        let row = T::json_schema(generator);
        let mut properties = Map::new();
        let fields = row.get("properties").and_then(Value::as_object);
        for (name, field) in fields.into_iter().flatten() {
            let (item, width) = match field.get("items") {
                Some(item) => (item, field.get("maxItems").cloned()),
                None => (field, None),
            };
            let dtype = match item.get("type").and_then(Value::as_str) {
                Some("boolean") => "?",
                Some("integer") => "i1",
                _ => "f8",
            };
            let shape = match width {
                Some(k) => json!(["n", k]),
                None => json!(["n"]),
            };
            let mut column = json!({
                "type": "object",
                "x-python-type": "numpy.ndarray",
                "x-python-dtype": dtype,
                "x-python-shape": shape,
            });
            if let (Some(doc), Some(map)) = (field.get("description"), column.as_object_mut()) {
                map.insert("description".into(), doc.clone());
            }
            properties.insert(name.clone(), column);
        }
        let required = row.get("required").cloned().unwrap_or_else(|| json!([]));
        json_schema!({ "type": "object", "properties": properties, "required": required })
    }
}

/// A column being collected: its dtype, width (`None` for a scalar field) and bytes.
struct Column {
    name: &'static str,
    dtype: Dtype,
    width: Option<usize>,
    data: Vec<u8>,
}

/// The columns of [`Columns`]; the first row (the default, `learning`) declares them, the
/// others must match field by field.
struct Table {
    columns: Vec<Column>,
    learning: bool,
    next: usize,
}

/// Why a row did not fit the columns (a bug in a row type, not a user's input).
#[derive(Debug)]
struct ColumnError(String);

impl fmt::Display for ColumnError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "time-series columns: {}", self.0)
    }
}

impl std::error::Error for ColumnError {}

impl ser::Error for ColumnError {
    fn custom<M: fmt::Display>(msg: M) -> Self {
        Self(msg.to_string())
    }
}

fn unsupported<T>(what: &str) -> Result<T, ColumnError> {
    Err(ColumnError(format!(
        "a row must be a struct of f64, bool, i8 or arrays of them; got {what}"
    )))
}

/// Serializes one row (a struct) into the table.
struct RowSerializer<'t>(&'t mut Table);

/// Serializes one field of a row into its column.
struct CellSerializer<'c> {
    column: &'c mut Column,
    /// Declaring the column (the default row): the first element sets its dtype.
    learning: bool,
    /// Whether the field is a `[_; k]`.
    in_array: bool,
    /// Elements written.
    elements: usize,
}

impl CellSerializer<'_> {
    fn push<E: Element>(&mut self, value: E) -> Result<(), ColumnError> {
        if self.learning && self.elements == 0 {
            self.column.dtype = E::DTYPE;
        }
        if self.column.dtype != E::DTYPE {
            return Err(ColumnError(format!(
                "column `{}` mixes dtypes",
                self.column.name
            )));
        }
        value.put(&mut self.column.data);
        self.elements += 1;
        Ok(())
    }
}

impl<'t> SerializeStruct for RowSerializer<'t> {
    type Ok = ();
    type Error = ColumnError;

    fn serialize_field<V: ?Sized + Serialize>(
        &mut self,
        key: &'static str,
        value: &V,
    ) -> Result<(), ColumnError> {
        let table = &mut *self.0;
        let learning = table.learning;
        if learning {
            table.columns.push(Column {
                name: key,
                dtype: Dtype::F64,
                width: None,
                data: Vec::new(),
            });
        }
        let index = table.next;
        table.next += 1;
        let column = table
            .columns
            .get_mut(index)
            .filter(|c| c.name == key)
            .ok_or_else(|| ColumnError(format!("field `{key}` is not a declared column")))?;
        let mut cell = CellSerializer {
            column,
            learning,
            in_array: false,
            elements: 0,
        };
        value.serialize(&mut cell)?;
        let width = cell.in_array.then_some(cell.elements);
        if width.is_none() && cell.elements != 1 {
            return Err(ColumnError(format!("field `{key}` is not a number")));
        }
        if learning {
            column.width = width;
        } else if column.width != width {
            return Err(ColumnError(format!(
                "field `{key}` changed its width between rows"
            )));
        }
        Ok(())
    }

    fn end(self) -> Result<(), ColumnError> {
        if self.0.next != self.0.columns.len() {
            return Err(ColumnError("a row skipped a field".into()));
        }
        Ok(())
    }
}

/// The [`Serializer`] methods both column serializers share: they refuse what a time-series
/// column cannot hold, and see through a newtype struct.
macro_rules! refuse_non_columns {
    () => {
        fn serialize_char(self, _: char) -> Result<(), ColumnError> {
            unsupported("a char")
        }
        fn serialize_str(self, _: &str) -> Result<(), ColumnError> {
            unsupported("a string")
        }
        fn serialize_bytes(self, _: &[u8]) -> Result<(), ColumnError> {
            unsupported("bytes")
        }
        fn serialize_none(self) -> Result<(), ColumnError> {
            unsupported("an option")
        }
        fn serialize_some<V: ?Sized + Serialize>(self, _: &V) -> Result<(), ColumnError> {
            unsupported("an option")
        }
        fn serialize_unit(self) -> Result<(), ColumnError> {
            unsupported("a unit")
        }
        fn serialize_unit_struct(self, _: &'static str) -> Result<(), ColumnError> {
            unsupported("a unit struct")
        }
        fn serialize_unit_variant(
            self,
            _: &'static str,
            _: u32,
            _: &'static str,
        ) -> Result<(), ColumnError> {
            unsupported("an enum")
        }
        fn serialize_newtype_struct<V: ?Sized + Serialize>(
            self,
            _: &'static str,
            value: &V,
        ) -> Result<(), ColumnError> {
            value.serialize(self)
        }
        fn serialize_newtype_variant<V: ?Sized + Serialize>(
            self,
            _: &'static str,
            _: u32,
            _: &'static str,
            _: &V,
        ) -> Result<(), ColumnError> {
            unsupported("an enum")
        }
        fn serialize_tuple_variant(
            self,
            _: &'static str,
            _: u32,
            _: &'static str,
            _: usize,
        ) -> Result<Self::SerializeTupleVariant, ColumnError> {
            unsupported("an enum")
        }
        fn serialize_struct_variant(
            self,
            _: &'static str,
            _: u32,
            _: &'static str,
            _: usize,
        ) -> Result<Self::SerializeStructVariant, ColumnError> {
            unsupported("an enum")
        }
    };
}

impl<'t> Serializer for RowSerializer<'t> {
    type Ok = ();
    type Error = ColumnError;
    type SerializeSeq = Impossible<(), ColumnError>;
    type SerializeTuple = Impossible<(), ColumnError>;
    type SerializeTupleStruct = Impossible<(), ColumnError>;
    type SerializeTupleVariant = Impossible<(), ColumnError>;
    type SerializeMap = Impossible<(), ColumnError>;
    type SerializeStruct = Self;
    type SerializeStructVariant = Impossible<(), ColumnError>;

    fn serialize_struct(self, _name: &'static str, _len: usize) -> Result<Self, ColumnError> {
        Ok(self)
    }

    fn serialize_bool(self, _: bool) -> Result<(), ColumnError> {
        unsupported("a bool row")
    }
    fn serialize_i8(self, _: i8) -> Result<(), ColumnError> {
        unsupported("an integer row")
    }
    fn serialize_i16(self, _: i16) -> Result<(), ColumnError> {
        unsupported("an integer row")
    }
    fn serialize_i32(self, _: i32) -> Result<(), ColumnError> {
        unsupported("an integer row")
    }
    fn serialize_i64(self, _: i64) -> Result<(), ColumnError> {
        unsupported("an integer row")
    }
    fn serialize_u8(self, _: u8) -> Result<(), ColumnError> {
        unsupported("an integer row")
    }
    fn serialize_u16(self, _: u16) -> Result<(), ColumnError> {
        unsupported("an integer row")
    }
    fn serialize_u32(self, _: u32) -> Result<(), ColumnError> {
        unsupported("an integer row")
    }
    fn serialize_u64(self, _: u64) -> Result<(), ColumnError> {
        unsupported("an integer row")
    }
    fn serialize_f32(self, _: f32) -> Result<(), ColumnError> {
        unsupported("a float row")
    }
    fn serialize_f64(self, _: f64) -> Result<(), ColumnError> {
        unsupported("a float row")
    }
    fn serialize_seq(self, _: Option<usize>) -> Result<Self::SerializeSeq, ColumnError> {
        unsupported("a sequence row")
    }
    fn serialize_tuple(self, _: usize) -> Result<Self::SerializeTuple, ColumnError> {
        unsupported("a tuple row")
    }
    fn serialize_tuple_struct(
        self,
        _: &'static str,
        _: usize,
    ) -> Result<Self::SerializeTupleStruct, ColumnError> {
        unsupported("a tuple struct row")
    }
    fn serialize_map(self, _: Option<usize>) -> Result<Self::SerializeMap, ColumnError> {
        unsupported("a map row")
    }
    refuse_non_columns!();
}

impl<'a, 'c> ser::SerializeTuple for &'a mut CellSerializer<'c> {
    type Ok = ();
    type Error = ColumnError;

    fn serialize_element<V: ?Sized + Serialize>(&mut self, value: &V) -> Result<(), ColumnError> {
        value.serialize(&mut **self)
    }

    fn end(self) -> Result<(), ColumnError> {
        Ok(())
    }
}

impl<'a, 'c> Serializer for &'a mut CellSerializer<'c> {
    type Ok = ();
    type Error = ColumnError;
    type SerializeSeq = Impossible<(), ColumnError>;
    type SerializeTuple = Self;
    type SerializeTupleStruct = Impossible<(), ColumnError>;
    type SerializeTupleVariant = Impossible<(), ColumnError>;
    type SerializeMap = Impossible<(), ColumnError>;
    type SerializeStruct = Impossible<(), ColumnError>;
    type SerializeStructVariant = Impossible<(), ColumnError>;

    fn serialize_f64(self, v: f64) -> Result<(), ColumnError> {
        self.push(v)
    }
    fn serialize_bool(self, v: bool) -> Result<(), ColumnError> {
        self.push(v)
    }
    fn serialize_i8(self, v: i8) -> Result<(), ColumnError> {
        self.push(v)
    }
    fn serialize_tuple(self, _len: usize) -> Result<Self, ColumnError> {
        if self.in_array {
            return unsupported("a nested array");
        }
        self.in_array = true;
        Ok(self)
    }

    fn serialize_i16(self, _: i16) -> Result<(), ColumnError> {
        unsupported("an i16")
    }
    fn serialize_i32(self, _: i32) -> Result<(), ColumnError> {
        unsupported("an i32")
    }
    fn serialize_i64(self, _: i64) -> Result<(), ColumnError> {
        unsupported("an i64")
    }
    fn serialize_u8(self, _: u8) -> Result<(), ColumnError> {
        unsupported("a u8")
    }
    fn serialize_u16(self, _: u16) -> Result<(), ColumnError> {
        unsupported("a u16")
    }
    fn serialize_u32(self, _: u32) -> Result<(), ColumnError> {
        unsupported("a u32")
    }
    fn serialize_u64(self, _: u64) -> Result<(), ColumnError> {
        unsupported("a u64")
    }
    fn serialize_f32(self, _: f32) -> Result<(), ColumnError> {
        unsupported("an f32")
    }
    fn serialize_seq(self, _: Option<usize>) -> Result<Self::SerializeSeq, ColumnError> {
        unsupported("a variable-length sequence")
    }
    fn serialize_tuple_struct(
        self,
        _: &'static str,
        _: usize,
    ) -> Result<Self::SerializeTupleStruct, ColumnError> {
        unsupported("a tuple struct")
    }
    fn serialize_map(self, _: Option<usize>) -> Result<Self::SerializeMap, ColumnError> {
        unsupported("a map")
    }
    fn serialize_struct(
        self,
        _: &'static str,
        _: usize,
    ) -> Result<Self::SerializeStruct, ColumnError> {
        unsupported("a nested struct")
    }
    refuse_non_columns!();
}
