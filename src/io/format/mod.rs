//! The heightfield formats, one file each (the table in [`crate::io`] says
//! what each keeps), and what several of them share: the JSON sidecar that
//! gives integer samples metres ([`sidecar`]) and the 16-bit code ↔ metre
//! mapping ([`quantize`]). Each format's `decode` / `encode` works on bytes;
//! [`crate::io`] picks the format and adds paths.

pub mod asc;
pub mod exr;
pub mod hgt;
pub mod png;
pub mod quantize;
pub mod raw;
pub mod sidecar;
pub mod ter;
pub mod tiff;
