//! Film: per-pixel accumulation and output.
