//! The page, embedded in the binary (nothing is fetched at run time, and
//! no file beside the binary is needed). Plain HTML, CSS and JavaScript
//! modules from `web/`, no third-party code.

/// Path under `/assets/` (and `index.html` for `/`), media type, bytes.
const FILES: &[(&str, &str, &[u8])] = &[
    (
        "index.html",
        "text/html; charset=utf-8",
        include_bytes!("../../../web/index.html"),
    ),
    (
        "editor.css",
        "text/css; charset=utf-8",
        include_bytes!("../../../web/editor.css"),
    ),
    (
        "js/main.js",
        "text/javascript; charset=utf-8",
        include_bytes!("../../../web/js/main.js"),
    ),
    (
        "js/api.js",
        "text/javascript; charset=utf-8",
        include_bytes!("../../../web/js/api.js"),
    ),
    (
        "js/link.js",
        "text/javascript; charset=utf-8",
        include_bytes!("../../../web/js/link.js"),
    ),
    (
        "js/save.js",
        "text/javascript; charset=utf-8",
        include_bytes!("../../../web/js/save.js"),
    ),
    (
        "js/map.js",
        "text/javascript; charset=utf-8",
        include_bytes!("../../../web/js/map.js"),
    ),
    (
        "js/view3d.js",
        "text/javascript; charset=utf-8",
        include_bytes!("../../../web/js/view3d.js"),
    ),
    (
        "js/geometry.js",
        "text/javascript; charset=utf-8",
        include_bytes!("../../../web/js/geometry.js"),
    ),
    (
        "js/controls.js",
        "text/javascript; charset=utf-8",
        include_bytes!("../../../web/js/controls.js"),
    ),
    (
        "js/draw.js",
        "text/javascript; charset=utf-8",
        include_bytes!("../../../web/js/draw.js"),
    ),
    (
        "js/tools.js",
        "text/javascript; charset=utf-8",
        include_bytes!("../../../web/js/tools.js"),
    ),
    (
        "js/panel.js",
        "text/javascript; charset=utf-8",
        include_bytes!("../../../web/js/panel.js"),
    ),
];

/// An embedded file by its path.
pub fn get(path: &str) -> Option<(&'static str, &'static [u8])> {
    FILES
        .iter()
        .find(|(p, _, _)| *p == path)
        .map(|(_, mime, bytes)| (*mime, *bytes))
}
