//! intel_tex_2 ships prebuilt ISPC kernels compiled as C++; with Rust's default linker they need
//! libstdc++ linked explicitly (see docs/dependencies.md).
fn main() {
    let target = std::env::var("TARGET").unwrap_or_default();
    if target.contains("linux") {
        println!("cargo:rustc-link-lib=dylib=stdc++");
    }
    println!("cargo:rerun-if-changed=build.rs");
}
