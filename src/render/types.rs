//! The colours the preview shows terrain types in (the masks themselves are
//! [`crate::io::TypeMask`]).

use crate::io::maps::type_mask::{NO_TYPE, TypeMask};
/// Default opacity of type colours over the terrain tint.
pub const DEFAULT_OPACITY: u8 = 150;

/// Distinct colours for type indices (Tableau-10 order, without red, which
/// means "out of range"); indices beyond the list reuse it.
pub const TYPE_COLOURS: [[u8; 3]; 9] = [
    [78, 121, 167],  // blue
    [242, 142, 43],  // orange
    [89, 161, 79],   // green
    [176, 122, 161], // purple
    [237, 201, 72],  // yellow
    [118, 183, 178], // teal
    [156, 117, 95],  // brown
    [255, 157, 167], // pink
    [186, 176, 172], // grey
];

/// The colour of type `index` (sRGB).
pub fn type_colour(index: u8) -> [u8; 3] {
    TYPE_COLOURS[index as usize % TYPE_COLOURS.len()]
}

/// A type mask and how to show it.
#[derive(Debug, Clone, PartialEq)]
pub struct TypeOverlay {
    pub mask: TypeMask,
    /// Colour and opacity per index; [`NO_TYPE`] is never drawn.
    pub colours: Box<[[u8; 4]; 256]>,
    /// How far the tint is moved toward grey (0 = kept), everywhere: the
    /// tint is one table. Muted, a map shows its painted types best; the
    /// editor keeps the tint, as the artist paints over a map they read.
    pub mute: f64,
}

impl TypeOverlay {
    /// The mask in the default colours at [`DEFAULT_OPACITY`].
    pub fn new(mask: TypeMask) -> TypeOverlay {
        let colours = Box::new(std::array::from_fn(|i| {
            let [r, g, b] = type_colour(i as u8);
            [
                r,
                g,
                b,
                if i == NO_TYPE as usize {
                    0
                } else {
                    DEFAULT_OPACITY
                },
            ]
        }));
        TypeOverlay {
            mask,
            colours,
            mute: crate::render::prepare::TYPES_MUTE,
        }
    }
}
