//! [`Values`]: the numbers of a column, owned or shared without a copy.
//!
//! Readers own what they parse (`Values::Owned`). A column made from memory
//! that already exists — a NumPy array handed over by the Python package —
//! can instead point at that memory (`Values::Shared`), so that a 10⁷-sample
//! flight built from arrays costs no copy. Reading goes through `Deref` to
//! `&[f64]` either way; the rare operations that change values in place
//! (row selection, unit scaling) first make a private copy
//! ([`Values::to_mut`], copy on write), so the shared memory is never
//! written.

use std::fmt;
use std::ops::Deref;
use std::sync::Arc;

/// Memory owned elsewhere that a column reads without copying.
///
/// The implementor guarantees that [`SharedBuffer::values`] returns the same
/// slice for the buffer's whole life and that the memory stays valid while
/// the buffer exists (e.g. by holding a reference to the array that owns it).
pub trait SharedBuffer: Send + Sync + fmt::Debug {
    /// The values.
    fn values(&self) -> &[f64];
}

/// The values of a numeric column.
#[derive(Clone)]
pub enum Values {
    /// Values the column owns.
    Owned(Vec<f64>),
    /// Values in memory owned elsewhere, never written through the column.
    Shared(Arc<dyn SharedBuffer>),
}

impl Values {
    /// The values as a vector this column owns, copying shared memory
    /// first (copy on write).
    pub fn to_mut(&mut self) -> &mut Vec<f64> {
        if let Values::Shared(b) = self {
            *self = Values::Owned(b.values().to_vec());
        }
        match self {
            Values::Owned(v) => v,
            Values::Shared(_) => unreachable!("made owned just above"),
        }
    }

    /// The values as an owned vector (copies shared memory).
    pub fn into_vec(self) -> Vec<f64> {
        match self {
            Values::Owned(v) => v,
            Values::Shared(b) => b.values().to_vec(),
        }
    }

    /// Whether the values are shared memory (not a copy).
    pub fn is_shared(&self) -> bool {
        matches!(self, Values::Shared(_))
    }
}

impl Deref for Values {
    type Target = [f64];
    fn deref(&self) -> &[f64] {
        match self {
            Values::Owned(v) => v,
            Values::Shared(b) => b.values(),
        }
    }
}

impl From<Vec<f64>> for Values {
    fn from(v: Vec<f64>) -> Self {
        Values::Owned(v)
    }
}

impl PartialEq for Values {
    fn eq(&self, other: &Self) -> bool {
        **self == **other
    }
}

impl fmt::Debug for Values {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Values::Owned(v) => f.debug_tuple("Owned").field(v).finish(),
            Values::Shared(b) => f.debug_tuple("Shared").field(b).finish(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug)]
    struct Fixed(Vec<f64>);
    impl SharedBuffer for Fixed {
        fn values(&self) -> &[f64] {
            &self.0
        }
    }

    #[test]
    fn shared_values_read_in_place_and_copy_on_write() {
        let buf = Arc::new(Fixed(vec![1.0, 2.0, 3.0]));
        let mut v = Values::Shared(buf.clone());
        assert!(v.is_shared());
        assert_eq!(v.as_ptr(), buf.0.as_ptr(), "no copy");
        assert_eq!(v, Values::Owned(vec![1.0, 2.0, 3.0]));
        v.to_mut()[0] = 10.0;
        assert!(!v.is_shared());
        assert_eq!(&v[..], &[10.0, 2.0, 3.0]);
        assert_eq!(
            buf.0,
            vec![1.0, 2.0, 3.0],
            "the shared memory is never written"
        );
    }
}
