//! The WGSL kernels compile (naga parses and validates each one, no GPU
//! needed), and every parameter block shared with Rust has the same size
//! and member offsets on both sides.

use std::mem::{offset_of, size_of};
use terrasynth::backend::kernels::{self, CorrectUniform, ReconstructUniform, UpsampleUniform};
use terrasynth::synth::atlas::Column;

fn module(k: kernels::Kernel) -> naga::Module {
    let src = k.module_source();
    let m = naga::front::wgsl::parse_str(&src)
        .unwrap_or_else(|e| panic!("{}.wgsl: {}", k.name, e.emit_to_string(&src)));
    naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::empty(),
    )
    .validate(&m)
    .unwrap_or_else(|e| panic!("{}.wgsl does not validate: {e:?}", k.name));
    m
}

/// (size, [(member, offset)]) of the WGSL struct `name`.
fn wgsl_struct(m: &naga::Module, name: &str) -> (u32, Vec<(String, u32)>) {
    for (_, ty) in m.types.iter() {
        if ty.name.as_deref() == Some(name)
            && let naga::TypeInner::Struct { members, span } = &ty.inner
        {
            let fields = members
                .iter()
                .map(|f| (f.name.clone().unwrap_or_default(), f.offset))
                .collect();
            return (*span, fields);
        }
    }
    panic!("struct {name} not found");
}

macro_rules! rust_layout {
    ($t:ty { $($f:ident),* $(,)? }) => {
        (
            size_of::<$t>() as u32,
            vec![$((stringify!($f).to_string(), offset_of!($t, $f) as u32)),*],
        )
    };
}

#[test]
fn every_kernel_parses_and_validates() {
    for k in kernels::ALL {
        let m = module(k);
        assert!(
            m.entry_points.iter().any(|e| e.name == "main"),
            "{} has no `main` entry point",
            k.name
        );
    }
}

#[test]
fn parameter_structs_match_their_wgsl_declarations() {
    let upsample = module(kernels::UPSAMPLE_JITTER);
    assert_eq!(
        wgsl_struct(&upsample, "UpsampleParams"),
        rust_layout!(UpsampleUniform {
            child_width,
            child_height,
            parent_width,
            seed,
            level,
            jitter,
            step,
            shift,
            min_x,
            max_x,
            min_y,
            max_y
        })
    );
    assert_eq!(
        wgsl_struct(&module(kernels::CORRECT), "CorrectParams"),
        rust_layout!(CorrectUniform {
            width,
            height,
            px,
            py
        })
    );
    assert_eq!(
        wgsl_struct(&module(kernels::RECONSTRUCT), "ReconstructParams"),
        rust_layout!(ReconstructUniform {
            width,
            height,
            pad0,
            pad1
        })
    );
    // The atlas column table is uploaded as the Rust slice's bytes.
    for k in kernels::ALL {
        assert_eq!(
            wgsl_struct(&module(k), "Column"),
            rust_layout!(Column {
                base,
                stride,
                min_x,
                max_x,
                max_y
            }),
            "Column in {}",
            k.name
        );
    }
}

#[test]
fn step_constants_match() {
    let src = kernels::UPSAMPLE_JITTER.source;
    for (name, v) in [
        ("STEP_PYRAMID", kernels::STEP_PYRAMID),
        ("STEP_VIRTUAL", kernels::STEP_VIRTUAL),
        ("STEP_WRAP", kernels::STEP_WRAP),
    ] {
        assert!(
            src.contains(&format!("const {name}: u32 = {v}u;")),
            "{name} must be {v} in upsample_jitter.wgsl"
        );
    }
    for k in kernels::ALL {
        assert!(
            k.source.contains(&format!(
                "@workgroup_size({}, {})",
                kernels::WORKGROUP,
                kernels::WORKGROUP
            )),
            "{} workgroup size",
            k.name
        );
    }
}
