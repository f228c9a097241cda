//! A 5 × 7 bitmap font for labels on generated pictures (plots, side-by-side
//! previews): embedded, so no system font is ever needed. Upper case,
//! digits and common punctuation; lower case is drawn as upper case, any
//! other character as `?`.

use image::{Rgba, RgbaImage};

/// Glyph height in font pixels (each glyph is 5 wide, plus 1 of spacing).
pub const GLYPH_HEIGHT: u32 = 7;
/// Advance per character in font pixels.
pub const ADVANCE: u32 = 6;

/// Rows top to bottom; bit 4 is the leftmost of the five columns.
type Glyph = [u8; 7];

/// The glyphs are data, kept in `data/font5x7.txt` where a glyph can be
/// read and edited as its rows: one line per glyph, the character in the
/// first column, then its seven rows as two-digit hex bytes, each after one
/// space (`A 0E 11 11 1F 11 11 11`). Parsed at compile time, so a malformed
/// line fails the build instead of a render.
static GLYPHS: [Option<Glyph>; 128] = parse_font(include_bytes!("../../data/font5x7.txt"));

/// Parses the font file's fixed-width lines into a table indexed by ASCII
/// code.
const fn parse_font(src: &[u8]) -> [Option<Glyph>; 128] {
    const fn hex(d: u8) -> u8 {
        match d {
            b'0'..=b'9' => d - b'0',
            b'A'..=b'F' => d - b'A' + 10,
            _ => panic!("font5x7.txt: a row is not two upper-case hex digits"),
        }
    }
    let mut table = [None; 128];
    let mut i = 0;
    while i < src.len() {
        let key = src[i];
        assert!(key < 128, "font5x7.txt: a glyph's character is not ASCII");
        let mut g = [0u8; 7];
        let mut row = 0;
        while row < 7 {
            let at = i + 1 + 3 * row;
            assert!(
                src[at] == b' ',
                "font5x7.txt: rows are separated by one space"
            );
            g[row] = hex(src[at + 1]) << 4 | hex(src[at + 2]);
            row += 1;
        }
        assert!(
            src[i + 22] == b'\n',
            "font5x7.txt: a glyph is one line of 7 rows"
        );
        table[key as usize] = Some(g);
        i += 23;
    }
    table
}

/// The glyph of `c` (lower case as upper case); `?` for a character the
/// font lacks.
fn glyph(c: char) -> Glyph {
    let known = |c: char| GLYPHS.get(c as usize).copied().flatten();
    known(c.to_ascii_uppercase())
        .or(known('?'))
        .expect("font5x7.txt has '?'")
}

/// Width in image pixels of `text` at `scale` (without trailing spacing).
pub fn text_width(text: &str, scale: u32) -> u32 {
    (text.chars().count() as u32 * ADVANCE).saturating_sub(1) * scale
}

/// Draws `text` with its top-left corner at (x, y), each font pixel a
/// `scale × scale` square; what falls outside the image is clipped.
pub fn draw_text(img: &mut RgbaImage, x: i64, y: i64, text: &str, scale: u32, colour: Rgba<u8>) {
    let s = scale as i64;
    for (k, c) in text.chars().enumerate() {
        let g = glyph(c);
        let gx = x + k as i64 * ADVANCE as i64 * s;
        for (row, bits) in g.iter().enumerate() {
            for col in 0..5 {
                if bits & (0x10 >> col) == 0 {
                    continue;
                }
                for dy in 0..s {
                    for dx in 0..s {
                        let (px, py) = (gx + col * s + dx, y + row as i64 * s + dy);
                        if px >= 0 && py >= 0 && px < img.width() as i64 && py < img.height() as i64
                        {
                            img.put_pixel(px as u32, py as u32, colour);
                        }
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every glyph a label uses is distinct from the fallback, and drawing
    /// sets exactly the glyph's pixels.
    #[test]
    fn glyphs_are_distinct_and_drawn_exactly() {
        let set = "ABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789 .,-+%()[]/:=|><_'^*!~#";
        let mut seen = std::collections::HashSet::new();
        for c in set.chars() {
            assert!(seen.insert(glyph(c)), "glyph {c:?} repeats another");
        }
        assert_eq!(glyph('a'), glyph('A'));
        let mut img = RgbaImage::new(12, 8);
        draw_text(&mut img, 0, 0, "1L", 1, Rgba([255; 4]));
        let lit = img.pixels().filter(|p| p.0[3] == 255).count() as u32;
        let bits = |c| glyph(c).iter().map(|b| b.count_ones()).sum::<u32>();
        assert_eq!(lit, bits('1') + bits('L'));
        assert_eq!(text_width("1L", 2), 22);
    }
}
