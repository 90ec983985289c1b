//! An effect's method and the reason for it: the row every part of the
//! render plan is made of.

use serde::{Deserialize, Serialize};

/// An effect's method and the reason for it.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Choice {
    pub method: String,
    pub reason: String,
}

pub(super) fn choice(method: &str, reason: impl Into<String>) -> Choice {
    Choice {
        method: method.into(),
        reason: reason.into(),
    }
}
