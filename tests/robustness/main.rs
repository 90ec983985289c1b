//! Robustness of the real binary: the seeded fuzzer, hostile and huge
//! input, and interruption by signals. One test binary: the tests run
//! `lucent` as a child process or render in-process without touching
//! process-wide state (environment, working directory, signal handlers).

#[path = "../common/mod.rs"]
mod common;

mod fuzz;
mod fuzz_files;
#[cfg(feature = "subsurface")]
mod fuzz_study;
mod hostile_files;
mod hostile_input;
mod huge_numbers;
mod interrupt;
mod part_forgery;
