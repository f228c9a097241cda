//! The GPU context of the cross-check tests (`--features gpu`).

use std::sync::{Arc, OnceLock};
use terrasynth::backend::{BackendError, gpu::Context};

/// Set (to anything) where an adapter is known to exist — `.ci/run`
/// installs lavapipe — so that the cross-checks cannot pass by skipping.
pub const REQUIRE_GPU: &str = "TERRASYNTH_REQUIRE_GPU";

/// Whether [`REQUIRE_GPU`] is set.
pub fn required() -> bool {
    std::env::var_os(REQUIRE_GPU).is_some()
}

/// The shared device, or `None` (with the reason printed) when there is no
/// adapter. Any other failure — a kernel that does not compile, a device
/// that refuses — is a bug, not a missing GPU, and panics; so does a
/// missing adapter under [`REQUIRE_GPU`].
pub fn context() -> Option<Arc<Context>> {
    static CTX: OnceLock<Result<Arc<Context>, BackendError>> = OnceLock::new();
    match CTX.get_or_init(Context::new) {
        Ok(c) => Some(c.clone()),
        Err(e @ BackendError::NoAdapter(_)) if !required() => {
            eprintln!("skipping the GPU cross-check: {e}");
            None
        }
        Err(e) => panic!("the GPU cross-check cannot run: {e}"),
    }
}
