//! Every WGSL shader parses and validates with naga (no GPU needed).

use pixelpie::gpu::util::{SHADERS, shader_source};

/// Every shader as compiled: the sampler's stages with the common prelude,
/// and the app's dot shader on its own.
fn sources() -> Vec<(&'static str, String)> {
    let mut v: Vec<_> = SHADERS
        .iter()
        .map(|(n, s)| (*n, shader_source(s)))
        .collect();
    v.push(("dots.wgsl", pixelpie::app::DOTS_SHADER.to_owned()));
    v
}

#[test]
fn every_wgsl_file_validates_with_naga() {
    for (name, source) in sources() {
        let module = naga::front::wgsl::parse_str(&source)
            .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(&source)));
        naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::empty(),
        )
        .validate(&module)
        .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(&source)));
    }
}

#[test]
fn every_file_in_shaders_is_compiled() {
    let mut on_disk: Vec<String> =
        std::fs::read_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/shaders"))
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            // The preludes: common.wgsl before every stage, empty.wgsl after
            // throw.wgsl and exact.wgsl.
            .filter(|n| n.ends_with(".wgsl") && n != "common.wgsl" && n != "empty.wgsl")
            .collect();
    on_disk.sort();
    let mut listed: Vec<String> = sources().into_iter().map(|(n, _)| n.to_owned()).collect();
    listed.sort();
    assert_eq!(on_disk, listed);
}
