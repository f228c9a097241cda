//! Fuzzes what the editor's HTTP API parses besides scene documents (those
//! have the `scene` target): query strings, the view body and the
//! new-session body. The first byte picks the parser.
#![no_main]

use libfuzzer_sys::fuzz_target;
use terrasynth::server::api::request;

fuzz_target!(|data: &[u8]| {
    let Some((&which, rest)) = data.split_first() else {
        return;
    };
    match which % 3 {
        0 => {
            let _ = request::view(rest);
        }
        1 => {
            let _ = request::new_session(rest);
        }
        _ => {
            let Ok(text) = std::str::from_utf8(rest) else {
                return;
            };
            if let Ok(pairs) = request::query(Some(text), &["commit", "format", "sidecar", "revision"]) {
                let _ = request::flag(&pairs, "commit", true);
                let _ = request::revision(&pairs);
                let _ = request::param(&pairs, "format");
            }
        }
    }
});
