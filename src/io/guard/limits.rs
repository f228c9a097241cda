//! How many decoded bytes a file of a given length can justify.
//!
//! Readers compare a header's declared size with these bounds *before*
//! allocating, so a tiny file that claims a huge grid is refused instead of
//! making us reserve gigabytes. Uncompressed formats need their exact byte
//! count; compressed ones are bounded by the best ratio their codec can reach.

use crate::io::FormatError;

/// Deflate (zlib, PNG, EXR ZIP, TIFF Deflate): one 258-byte match costs at
/// least ~2 bits (RFC 1951), so no stream expands more than 1032×.
pub const DEFLATE_RATIO: u64 = 1032;
/// TIFF LZW: no code is shorter than 9 bits and none emits more than 4096
/// bytes (the 12-bit table size), so 4096 / 1.125 bytes per code.
pub const LZW_RATIO: u64 = 3641;
/// ZSTD: an RLE block spends 4 bytes (3-byte header, 1 byte) on at most
/// 128 KiB of output (RFC 8878, Block_Maximum_Size).
pub const ZSTD_RATIO: u64 = 32768;
/// LERC (TIFF 34887): a constant chunk is one Lerc2 header whatever its
/// size (70 bytes as GDAL writes it, 50 with its deflate layer), so the
/// ratio is bounded only by the chunk size. With its 8 bytes of offset and
/// byte count, a constant 1024² Float64 tile (8 MiB, the largest block of
/// the COGs that use LERC) costs 58 bytes of file: 144 631×, rounded up.
pub const LERC_RATIO: u64 = 1 << 18;
/// PackBits: a 2-byte run emits at most 128 bytes.
pub const PACKBITS_RATIO: u64 = 64;
/// Fixed allowance for headers, tables and block padding, so that tiny
/// legitimate images are never refused.
pub const SLACK_BYTES: u64 = 4096;

/// Refuses `width × height × bytes_per_sample` decoded bytes from a
/// `file_len`-byte file compressed at most `ratio`×.
pub fn check_justified(
    width: usize,
    height: usize,
    bytes_per_sample: u64,
    file_len: usize,
    ratio: u64,
) -> Result<(), FormatError> {
    let raw = (width as u64)
        .saturating_mul(height as u64)
        .saturating_mul(bytes_per_sample);
    if raw
        > (file_len as u64)
            .saturating_mul(ratio)
            .saturating_add(SLACK_BYTES)
    {
        return Err(FormatError::not_justified(width, height, file_len));
    }
    Ok(())
}
