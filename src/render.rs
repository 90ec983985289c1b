//! Rendering driver.
