//! The canonical names of the core's statuses ([`Mode`], [`StepStatus`], [`RiccatiStatus`],
//! [`Fault`]): one snake_case string per value, used by `as_str`, `Display`, `FromStr` and,
//! with the `serde` feature, serialization. A [`FaultSet`] is written as its faults' names
//! (comma-separated in `Display`/`FromStr`, a sequence in serde). This module holds what they
//! share: the parse error and the serde plumbing.
//!
//! [`Mode`]: crate::safety::Mode
//! [`StepStatus`]: crate::control::StepStatus
//! [`RiccatiStatus`]: crate::lqr::RiccatiStatus
//! [`Fault`]: crate::safety::Fault
//! [`FaultSet`]: crate::safety::FaultSet

use core::fmt;

/// A string that is not the name of any value of a status type (`Mode`, `StepStatus`,
/// `RiccatiStatus`, `Fault`, `FaultSet`): the error of their `FromStr` parses.
///
/// ```
/// use ballbot_core::ParseNameError;
/// use ballbot_core::safety::Mode;
/// let err = "Balancing".parse::<Mode>().unwrap_err(); // names are snake_case
/// assert_eq!(err, ParseNameError::new("mode"));
/// assert_eq!(err.to_string(), "not the name of a mode");
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ParseNameError {
    what: &'static str,
}

impl ParseNameError {
    /// The error for a string that names no value of the type `what` describes (`"mode"`,
    /// `"step status"`, `"fault"`).
    ///
    /// ```
    /// use ballbot_core::ParseNameError;
    /// assert_eq!(ParseNameError::new("fault").what(), "fault");
    /// ```
    pub const fn new(what: &'static str) -> Self {
        Self { what }
    }

    /// What the string should have named (`"mode"`, `"step status"`, `"fault"`).
    ///
    /// ```
    /// use ballbot_core::control::StepStatus;
    /// let err = "ok".parse::<StepStatus>().unwrap_err();
    /// assert_eq!(err.what(), "step status");
    /// ```
    pub const fn what(&self) -> &'static str {
        self.what
    }
}

impl fmt::Display for ParseNameError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "not the name of a {}", self.what)
    }
}

impl core::error::Error for ParseNameError {}

/// The value of `T` named `name` among `all`, by `name_of`.
pub(crate) fn parse_name<T: Copy, const N: usize>(
    name: &str,
    all: &[T; N],
    name_of: fn(&T) -> &'static str,
    what: &'static str,
) -> Result<T, ParseNameError> {
    all.iter()
        .find(|v| name_of(v) == name)
        .copied()
        .ok_or(ParseNameError::new(what))
}

/// Serde plumbing: a named value is serialized as its name and deserialized from it.
#[cfg(feature = "serde")]
pub(crate) mod serde_name {
    use super::ParseNameError;
    use core::fmt;
    use core::marker::PhantomData;
    use core::str::FromStr;
    use serde::de::{self, Deserializer, Visitor};

    /// Deserializes a `T` from its name; `what` names `T` in the error.
    pub(crate) fn deserialize<'de, D, T>(deserializer: D, what: &'static str) -> Result<T, D::Error>
    where
        D: Deserializer<'de>,
        T: FromStr<Err = ParseNameError>,
    {
        deserializer.deserialize_str(NameVisitor(PhantomData, what))
    }

    struct NameVisitor<T>(PhantomData<T>, &'static str);

    impl<T: FromStr<Err = ParseNameError>> Visitor<'_> for NameVisitor<T> {
        type Value = T;

        fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
            write!(f, "the name of a {}", self.1)
        }

        fn visit_str<E: de::Error>(self, v: &str) -> Result<T, E> {
            v.parse()
                .map_err(|_| E::invalid_value(de::Unexpected::Str(v), &self))
        }
    }
}
