//! Burley normalized diffusion BSSRDF.
