//! Serde structures of the TOML scene format.
