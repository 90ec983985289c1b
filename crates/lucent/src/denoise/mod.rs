//! Denoising a finished frame with Intel Open Image Denoise 2, loaded at
//! run time like Embree 4 ([`load`]): the beauty, guided by the frame's
//! `albedo` and `N` passes, becomes the layer [`frame::LAYER`] beside the
//! noisy beauty. Used by `lucent render --denoise`, `lucent merge
//! --denoise` and `lucent denoise` (docs/output.md, "Denoising"; what it
//! buys and where it biases: docs/accuracy.md, "Denoising").

pub mod ffi;
pub mod filter;
pub mod frame;
pub mod load;

pub use filter::{denoise, DenoiseInput, DenoiseOptions};
