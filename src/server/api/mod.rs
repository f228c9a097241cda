//! The editor's HTTP side: the endpoints (`routes.rs`, with the API
//! table), what a request carries (`request.rs`), what an answer that
//! cannot be served says (`error.rs`), the embedded page (`assets.rs`), and
//! what comes out of a session besides frames (`output.rs`). The editing
//! itself is in `super::editor` and `super::document`.

mod assets;
pub(super) mod error;
mod output;
pub mod request;
pub(super) mod routes;
