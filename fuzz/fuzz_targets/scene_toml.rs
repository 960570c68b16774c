//! Fuzz target: arbitrary bytes through the scene toml loader, then prepared and
//! rendered when they load (`continuum_tests::untrusted::exercise`).
#![no_main]

use continuum_tests::untrusted::{Format, exercise};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    // libfuzzer-sys aborts on every panic, even one the loaders catch (the
    // gltf crate panics on some malformed accessors; we turn that into an
    // error): report panics, and let an uncaught one reach libfuzzer-sys's
    // own catch, which still aborts.
    static HOOK: std::sync::Once = std::sync::Once::new();
    HOOK.call_once(|| std::panic::set_hook(Box::new(|info| eprintln!("{info}"))));
    let _ = exercise(Format::SceneToml, data);
});
