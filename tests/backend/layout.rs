//! The WGSL kernels compile (naga parses and validates each one, no GPU
//! needed), and every parameter block shared with Rust has the same size
//! and member offsets on both sides.

use std::mem::{offset_of, size_of};
use terrasynth::backend::kernels;
use terrasynth::level::atlas::Column;
use terrasynth::stages::Stage;
use terrasynth::stages::correct::{CorrectUniform, GuideCell};
use terrasynth::stages::fill_ssd::FillSsdUniform;
use terrasynth::stages::reconstruct::ReconstructUniform;
use terrasynth::stages::reduce_types::ReduceTypesUniform;
use terrasynth::stages::reduce_weights::ReduceWeightsUniform;
use terrasynth::stages::shade::ShadeParams;
use terrasynth::stages::upsample_jitter::UpsampleUniform;

fn module(k: Stage) -> naga::Module {
    module_info(k).0
}

fn module_info(k: Stage) -> (naga::Module, naga::valid::ModuleInfo) {
    let src = kernels::module_source(k);
    let m = naga::front::wgsl::parse_str(&src)
        .unwrap_or_else(|e| panic!("{}.wgsl: {}", k.name(), e.emit_to_string(&src)));
    let info = naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::empty(),
    )
    .validate(&m)
    .unwrap_or_else(|e| panic!("{}.wgsl does not validate: {e:?}", k.name()));
    (m, info)
}

/// DESIGN §6: kernels compute in integers only (GPU float arithmetic is not
/// reproducible). Every expression's resolved type, every declared type and
/// every local variable is checked for a floating-point scalar.
#[test]
fn kernels_use_no_floating_point() {
    let is_float = |t: &naga::TypeInner| {
        matches!(
            t.scalar_kind(),
            Some(naga::ScalarKind::Float | naga::ScalarKind::AbstractFloat)
        )
    };
    for k in Stage::ALL {
        let (m, info) = module_info(k);
        for (_, t) in m.types.iter() {
            assert!(!is_float(&t.inner), "{}: float type {:?}", k.name(), t.name);
        }
        let functions = m.functions.iter().map(|(h, f)| (f, &info[h])).chain(
            m.entry_points
                .iter()
                .enumerate()
                .map(|(i, e)| (&e.function, info.get_entry_point(i))),
        );
        let mut checked = 0;
        for (f, fi) in functions {
            for (h, e) in f.expressions.iter() {
                let ty = fi[h].ty.inner_with(&m.types);
                assert!(
                    !is_float(ty),
                    "{}: {:?} in {:?} has a float type",
                    k.name(),
                    e,
                    f.name
                );
                checked += 1;
            }
        }
        assert!(
            checked > 50,
            "{}: only {checked} expressions seen",
            k.name()
        );
    }
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

/// Every kernel binds at most WebGPU's default number of storage buffers
/// per shader stage (8), so any adapter that wgpu accepts can run it, not
/// only those whose drivers raise the limit (lavapipe, desktop Vulkan).
#[test]
fn kernels_fit_the_default_storage_buffer_limit() {
    let limit = WEBGPU_DEFAULT_STORAGE_BUFFERS;
    for k in Stage::ALL {
        let m = module(k);
        let n = m
            .global_variables
            .iter()
            .filter(|(_, v)| matches!(v.space, naga::AddressSpace::Storage { .. }))
            .count();
        assert!(
            n <= limit,
            "{} binds {n} storage buffers: the default limit is {limit}",
            k.name()
        );
    }
}

/// `wgpu::Limits::default().max_storage_buffers_per_shader_stage`, the
/// WebGPU default (wgpu is no dependency of the tests without `gpu`).
const WEBGPU_DEFAULT_STORAGE_BUFFERS: usize = 8;

#[test]
fn every_kernel_parses_and_validates() {
    for k in Stage::ALL {
        let m = module(k);
        assert!(
            m.entry_points
                .iter()
                .any(|e| e.name == kernels::ENTRY_POINT),
            "{} has no `{}` entry point",
            k.name(),
            kernels::ENTRY_POINT
        );
    }
}

#[test]
fn parameter_structs_match_their_wgsl_declarations() {
    let upsample = module(Stage::UpsampleJitter);
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
            max_y,
            origin_x,
            origin_y,
            pad0,
            pad1
        })
    );
    assert_eq!(
        wgsl_struct(&module(Stage::Correct), "CorrectParams"),
        rust_layout!(CorrectUniform {
            width,
            height,
            px,
            py,
            flags,
            level,
            type_count,
            prior,
            x0,
            y0,
            x1,
            y1,
            parent_width,
            parent_height,
            has_parent,
            origin_x,
            origin_y,
            similar,
            pad1,
            pad2
        })
    );
    assert_eq!(
        wgsl_struct(&module(Stage::FillSsd), "FillSsdParams"),
        rust_layout!(FillSsdUniform {
            cells,
            candidates,
            transforms,
            pad0
        })
    );
    assert_eq!(
        wgsl_struct(&module(Stage::Correct), "GuideCell"),
        rust_layout!(GuideCell {
            blend_target,
            allowed,
            weight,
            prev_s,
            prev_v,
            pad0
        })
    );
    assert_eq!(
        wgsl_struct(&module(Stage::ReduceTypes), "ReduceTypesParams"),
        rust_layout!(ReduceTypesUniform {
            width,
            height,
            child_width,
            child_height,
            full,
            pad0,
            pad1,
            pad2
        })
    );
    assert_eq!(
        wgsl_struct(&module(Stage::ReduceWeights), "ReduceWeightsParams"),
        rust_layout!(ReduceWeightsUniform {
            width,
            height,
            child_width,
            child_height
        })
    );
    for k in [Stage::Reconstruct, Stage::RepairExtrema] {
        assert_eq!(
            wgsl_struct(&module(k), "ReconstructParams"),
            rust_layout!(ReconstructUniform {
                width,
                height,
                pad0,
                pad1
            }),
            "ReconstructParams in {}",
            k.name()
        );
    }
    assert_eq!(
        wgsl_struct(&module(Stage::Shade), "ShadeParams"),
        rust_layout!(ShadeParams {
            lights,
            width,
            height,
            flags,
            light_count,
            slope_x_mul,
            slope_x_pre,
            slope_x_post,
            slope_x_clamp,
            slope_y_mul,
            slope_y_pre,
            slope_y_post,
            slope_y_clamp,
            shade_floor,
            shade_gain,
            shade_max,
            nodata_colour,
            tint_lo,
            tint_shift,
            tint_len,
            nodata_hatch,
            water_level,
            water_shift,
            water_shallow,
            water_deep,
            range_lo,
            range_hi,
            range_colour,
            coast_colour,
            contour_base,
            contour_interval,
            contour_index_every,
            contour_colour,
            contour_half_width,
            index_half_width,
            coast_half_width,
            index_colour,
            contour_min_spacing,
            grid_step_x,
            grid_step_y,
            grid_colour
        })
    );
    // The atlas column table is uploaded as the Rust slice's bytes.
    for k in [
        Stage::UpsampleJitter,
        Stage::Correct,
        Stage::Reconstruct,
        Stage::RepairExtrema,
    ] {
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
            k.name()
        );
    }
}

#[test]
fn shade_constants_match() {
    use terrasynth::stages::shade::{self, flags};
    let src = Stage::Shade.wgsl();
    for (name, v) in [
        ("F_CONTOURS", flags::CONTOURS),
        ("F_GRID", flags::GRID),
        ("F_RANGE", flags::RANGE),
        ("F_SEA", flags::SEA),
        ("F_TYPES", flags::TYPES),
        ("F_ASPECT_WEIGHTS", flags::ASPECT_WEIGHTS),
        ("NO_TYPE", shade::NO_TYPE),
        ("FULL", shade::FULL),
    ] {
        assert!(
            src.contains(&format!("const {name}: u32 = {v}u;")),
            "{name} must be {v} in shade.wgsl"
        );
    }
    for (name, v) in [
        ("SLOPE_ONE", shade::SLOPE_ONE),
        ("MAX_SLOPE", shade::MAX_SLOPE),
    ] {
        assert!(
            src.contains(&format!("const {name}: i32 = {v};")),
            "{name} must be {v} in shade.wgsl"
        );
    }
    assert_eq!(shade::NODATA, i32::MIN);
    assert!(src.contains("const NODATA: i32 = -2147483647 - 1;"));
}

#[test]
fn correct_constants_match() {
    use terrasynth::database::types::SEEDS_PER_TYPE;
    use terrasynth::stages::correct::nudge::{DETAIL_LEVELS, DETAIL_STEP, KEEP_DETAIL, MAX_ERROR};
    use terrasynth::stages::correct::{
        CORRECT_ALLOWED, CORRECT_COHERENCE, CORRECT_TARGETS, FLAT, FLAT_FIT, SEED_SALT,
        SEEDS_PER_ALLOWED_TYPE, W_FREE,
    };
    let src = Stage::Correct.wgsl();
    for (name, v) in [
        ("F_TARGETS", CORRECT_TARGETS),
        ("F_ALLOWED", CORRECT_ALLOWED),
        ("F_COHERENCE", CORRECT_COHERENCE),
        ("W_FREE", W_FREE as u32),
        ("DETAIL_LEVELS", DETAIL_LEVELS),
        ("SEEDS_PER_ALLOWED_TYPE", SEEDS_PER_ALLOWED_TYPE),
        ("SEED_SALT", SEED_SALT),
        ("SEEDS_PER_TYPE", SEEDS_PER_TYPE as u32),
    ] {
        assert!(
            src.contains(&format!("const {name}: u32 = {v}u;")),
            "{name} must be {v} in correct.wgsl"
        );
    }
    for (name, v) in [
        ("MAX_ERROR", MAX_ERROR),
        ("KEEP_DETAIL", KEEP_DETAIL),
        ("DETAIL_STEP", DETAIL_STEP),
        ("FLAT_WEIGHT", FLAT.weight as i32),
        ("FLAT_FIT_WEIGHT", FLAT_FIT.weight as i32),
    ] {
        assert!(
            src.contains(&format!("const {name}: i32 = {v};")),
            "{name} must be {v} in correct.wgsl"
        );
    }
}

#[test]
fn reconstruct_constants_match() {
    use terrasynth::stages::repair_extrema::{DIMPLE_SHIFT, DIMPLE_SUPPORT, SUPPORT};
    for (name, v) in [
        ("SUPPORT", SUPPORT),
        ("DIMPLE_SUPPORT", DIMPLE_SUPPORT),
        ("DIMPLE_SHIFT", DIMPLE_SHIFT),
    ] {
        assert!(
            Stage::RepairExtrema
                .wgsl()
                .contains(&format!("const {name}: u32 = {v}u;")),
            "{name} must be {v} in repair_extrema.wgsl"
        );
    }
}

/// The constants several kernels share are declared once, in
/// `common.wgsl`, with the values of their Rust twins — and in no stage's
/// own file, where a second copy could drift.
#[test]
fn common_constants_match() {
    use terrasynth::database::appearance::MODE1_BIAS;
    use terrasynth::stages::common::ALL_TYPES;
    assert_eq!(ALL_TYPES, u32::MAX);
    for decl in [
        format!("const ALL_TYPES: u32 = {ALL_TYPES}u;"),
        format!("const MODE1_BIAS: i32 = {MODE1_BIAS};"),
    ] {
        assert_eq!(
            kernels::COMMON.matches(&decl).count(),
            1,
            "{decl} in common.wgsl"
        );
        let name = decl.split(':').next().expect("a declaration");
        for k in Stage::ALL {
            assert!(
                !k.wgsl().contains(name),
                "{name} declared again in {}.wgsl",
                k.name()
            );
        }
    }
}

#[test]
fn step_constants_match() {
    use terrasynth::stages::upsample_jitter::{STEP_PYRAMID, STEP_VIRTUAL, STEP_WRAP};
    let src = Stage::UpsampleJitter.wgsl();
    for (name, v) in [
        ("STEP_PYRAMID", STEP_PYRAMID),
        ("STEP_VIRTUAL", STEP_VIRTUAL),
        ("STEP_WRAP", STEP_WRAP),
    ] {
        assert!(
            src.contains(&format!("const {name}: u32 = {v}u;")),
            "{name} must be {v} in upsample_jitter.wgsl"
        );
    }
    for k in Stage::ALL {
        assert!(
            k.wgsl().contains(&format!(
                "@workgroup_size({}, {})",
                kernels::WORKGROUP,
                kernels::WORKGROUP
            )),
            "{} workgroup size",
            k.name()
        );
    }
}
