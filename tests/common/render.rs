//! Options and pixel access shared by the preview renderer's tests.

use terrasynth::render::{Contours, Light, Lighting, Palette, RenderOptions, Sea};

/// The grey of [`plain`]'s palette.
pub const GREY: [u8; 3] = [200, 200, 200];

/// Options that isolate one feature: a constant grey palette, no contours,
/// no water, no resizing.
pub fn plain() -> RenderOptions {
    RenderOptions {
        min_size: 1,
        contours: Contours::Off,
        sea: Sea::Off,
        palette: Palette::new(vec![(0.0, GREY), (1.0, GREY)]).unwrap(),
        ..RenderOptions::default()
    }
}

/// A single light from the west at 45°.
pub fn west_light() -> Lighting {
    Lighting {
        lights: vec![Light {
            azimuth_deg: 270.0,
            altitude_deg: 45.0,
            weight: 1.0,
        }],
        aspect_weighted: false,
        shadow: 0.25,
        highlight: 0.5,
    }
}

/// The RGBA bytes of pixel `(x, y)`.
pub fn px(img: &image::RgbaImage, x: u32, y: u32) -> [u8; 4] {
    img.get_pixel(x, y).0
}
