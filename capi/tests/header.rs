//! `include/guiding.h` is what cbindgen makes of `src/` today: regenerate
//! it with `GUIDING_BLESS=1 cargo test -p guiding-c --test header` after
//! changing the API.

use std::path::PathBuf;

#[test]
fn the_committed_header_is_current() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let config = cbindgen::Config::from_file(dir.join("cbindgen.toml")).expect("cbindgen.toml");
    let mut generated = Vec::new();
    cbindgen::Builder::new()
        .with_crate(&dir)
        .with_config(config)
        .generate()
        .expect("cbindgen reads the crate")
        .write(&mut generated);
    let path = dir.join("include/guiding.h");
    if std::env::var_os("GUIDING_BLESS").is_some() {
        std::fs::write(&path, &generated).expect("write the header");
        return;
    }
    let committed = std::fs::read(&path).unwrap_or_default();
    assert!(
        committed == generated,
        "capi/include/guiding.h is stale: rerun with GUIDING_BLESS=1 cargo test -p guiding-c --test header"
    );
}
