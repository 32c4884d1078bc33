//! The C API from C: `tests/c/glt_test.c` built with the system's C
//! compiler against the static library, run (under valgrind's memcheck
//! when it is installed: no error, no leak), and the header compiled as
//! C99 and as C++17 with every warning an error; `tests/cpp/nee_test.cpp`
//! drives a renderer's NEE through the C++ wrapper (`include/guiding.hpp`)
//! from four threads, under valgrind the same way.

use std::path::{Path, PathBuf};
use std::process::Command;

fn crate_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// `libguiding_c.a` of this very source: cargo builds only the rlib for
/// integration tests, so the test asks it for the static library (in the
/// test's own profile folder, beside its `deps/`), and links that.
fn library_dir() -> PathBuf {
    let exe = std::env::current_exe().expect("the test's path");
    let dir = exe
        .parent()
        .and_then(Path::parent)
        .expect("target/<profile>")
        .to_path_buf();
    let mut cargo = Command::new(env!("CARGO"));
    cargo.args(["build", "--quiet", "--lib", "-p", "guiding-c"]);
    if dir.file_name().is_some_and(|n| n == "release") {
        cargo.arg("--release");
    }
    run(cargo.current_dir(crate_dir()));
    dir
}

fn run(cmd: &mut Command) -> String {
    let out = cmd.output().unwrap_or_else(|e| panic!("{cmd:?}: {e}"));
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(out.status.success(), "{cmd:?} failed:\n{text}");
    text
}

fn on_path(tool: &str) -> bool {
    Command::new(tool)
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success())
}

/// Builds `source` (C99 or C++17, every warning an error) against the
/// static library and runs it, under valgrind's memcheck when installed;
/// returns what it printed.
fn build_and_run(source: &str, cpp: bool) -> String {
    let lib = library_dir();
    assert!(
        lib.join("libguiding_c.a").exists(),
        "no libguiding_c.a in {}",
        lib.display()
    );
    let name = Path::new(source).file_stem().expect("a file name");
    let exe = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(name);
    let dir = crate_dir();
    let (compiler, std) = if cpp {
        ("c++", "-std=c++17")
    } else {
        ("cc", "-std=c99")
    };
    run(Command::new(compiler)
        .args([
            std,
            "-Wall",
            "-Wextra",
            "-Werror",
            "-pedantic",
            "-O1",
            "-g",
            "-pthread",
        ])
        .arg(dir.join(source))
        .arg("-I")
        .arg(dir.join("include"))
        .arg(lib.join("libguiding_c.a"))
        .args(["-lpthread", "-ldl", "-lm", "-o"])
        .arg(&exe));
    if on_path("valgrind") {
        run(Command::new("valgrind")
            .args([
                "--error-exitcode=3",
                "--leak-check=full",
                "--errors-for-leak-kinds=definite,indirect",
                "--quiet",
            ])
            .arg(&exe))
    } else {
        run(&mut Command::new(&exe))
    }
}

#[test]
fn the_c_program_trains_checks_saves_loads_and_merges() {
    let out = build_and_run("tests/c/glt_test.c", false);
    assert!(out.contains("every check passed"), "{out}");
}

#[test]
fn the_sd_tree_and_the_field_from_c() {
    let out = build_and_run("tests/c/directions_test.c", false);
    assert!(out.contains("every check passed"), "{out}");
}

#[test]
fn the_cpp_wrapper_drives_a_renderers_nee_from_four_threads() {
    let out = build_and_run("tests/cpp/nee_test.cpp", true);
    assert!(out.contains("every check passed"), "{out}");
}

#[test]
fn the_header_is_clean_c99_and_cpp17() {
    let dir = crate_dir();
    let tmp = PathBuf::from(env!("CARGO_TARGET_TMPDIR"));
    let source = tmp.join("header_only.c");
    std::fs::write(
        &source,
        "#include \"guiding.h\"\nint main(void) { return guiding_last_error() == 0; }\n",
    )
    .expect("write");
    for (compiler, std, lang) in [("cc", "-std=c99", "c"), ("c++", "-std=c++17", "c++")] {
        run(Command::new(compiler)
            .args([
                std,
                "-Wall",
                "-Wextra",
                "-Werror",
                "-pedantic",
                "-fsyntax-only",
                "-x",
                lang,
            ])
            .arg(&source)
            .arg("-I")
            .arg(dir.join("include")));
    }
}
