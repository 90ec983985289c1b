//! Area lights.
