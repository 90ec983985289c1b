//! Embree backend (placeholder until the FFI lands).
