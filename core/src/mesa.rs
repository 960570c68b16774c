//! The process environment Mesa's drivers expect (they serve `gpu-raster`
//! and the viewer's window on machines without a GPU).

/// A private runtime folder for Mesa when the environment names none: Mesa's
/// Vulkan and OpenGL drivers print `XDG_RUNTIME_DIR is invalid or not set`
/// (harmless, but it reads like an error of ours) on every device they open.
/// Returns the folder (`$TMPDIR/continuum-runtime-UID`, mode 0700, created if
/// missing) for the binary to set as `XDG_RUNTIME_DIR` before it starts any
/// thread, or `None` when one is set or the folder cannot be made ours.
#[cfg(unix)]
pub fn private_runtime_dir() -> Option<std::path::PathBuf> {
    use std::os::unix::fs::{DirBuilderExt, MetadataExt, PermissionsExt};
    if std::env::var_os("XDG_RUNTIME_DIR").is_some() {
        return None;
    }
    let uid = std::fs::metadata("/proc/self").ok()?.uid();
    let dir = std::env::temp_dir().join(format!("continuum-runtime-{uid}"));
    let _ = std::fs::DirBuilder::new().mode(0o700).create(&dir);
    let meta = std::fs::symlink_metadata(&dir).ok()?;
    (meta.is_dir() && meta.uid() == uid && meta.permissions().mode() & 0o777 == 0o700)
        .then_some(dir)
}

/// Mesa's runtime folder is a Unix matter.
#[cfg(not(unix))]
pub fn private_runtime_dir() -> Option<std::path::PathBuf> {
    None
}
