//! Where the feature patches go (stages 1 and 2 of the pipeline): the
//! blurred sketch field, PPA and the feature graphs on it, and the user
//! patches placed breadth-first along the sketch's features.

use crate::patch::input::graph::FeatureGraph;
use crate::patch::input::ppa;
use crate::patch::input::sketch::{Kind, Sketch};
use crate::patch::merge::broad_shape::box_blur;
use crate::patch::place::candidates::{self, FeatureNode};

/// A user patch: where, what kind, and its description on the sketch.
#[derive(Debug, Clone)]
pub struct UserPatch {
    pub kind: Kind,
    pub node: FeatureNode,
}

/// The signed sketch field at output size, lightly blurred (three box passes
/// of radius patch/16) so that flat image strokes get a crest for PPA.
pub fn sketch_field(sketch: &Sketch, w: usize, h: usize, patch: usize) -> Vec<f32> {
    let mut f = sketch.raster(w, h);
    let r = (patch / 16).max(1);
    for _ in 0..3 {
        f = box_blur(&f, w, h, r);
    }
    f
}

/// PPA parameters for the sketch field (values in `[-1, 1]`): a dip of 0.1,
/// profiles of patch/4, and side branches shorter than patch/2 removed —
/// longer than on DEMs because a thick stroke's junction is a small plateau
/// on which the spanning tree grows spurs up to a stroke width long, while
/// every intended sketch line is far longer than half a patch.
pub fn sketch_ppa_params(patch: usize) -> ppa::PpaParams {
    ppa::PpaParams {
        min_branch: patch as f32 / 2.0,
        passes: 8,
        ..candidates::ppa_params(patch, 1.0, 0.1)
    }
}

/// Junctions of the sketch closer than this (along their path) are one
/// (thick strokes meeting at a point give two or three close junctions).
pub fn sketch_merge_len(patch: usize) -> f32 {
    patch as f32 / 4.0
}

/// PPA and the feature graph of one kind on the sketch field.
pub fn sketch_graph(
    field: &[f32],
    w: usize,
    h: usize,
    patch: usize,
    kind: Kind,
) -> (ppa::Tree, FeatureGraph) {
    let f: Vec<f32> = match kind {
        Kind::Ridge => field.to_vec(),
        Kind::Valley => field.iter().map(|v| -v).collect(),
    };
    let tree = ppa::extract(w, h, &f, &sketch_ppa_params(patch));
    let g = FeatureGraph::from_tree(&tree, sketch_merge_len(patch));
    (tree, g)
}

/// The sketch's feature graphs and user patches, in placement order
/// (ridges, then valleys).
pub fn user_patches(
    field: &[f32],
    w: usize,
    h: usize,
    patch: usize,
) -> (FeatureGraph, FeatureGraph, Vec<UserPatch>) {
    let r = patch as f32 / 4.0;
    let neg: Vec<f32> = field.iter().map(|v| -v).collect();
    let mut out = Vec::new();
    let mut graphs = Vec::new();
    for (kind, f) in [(Kind::Ridge, field), (Kind::Valley, &neg[..])] {
        let (_, g) = sketch_graph(field, w, h, patch, kind);
        let idx = g.exit_index();
        for c in g.placements(patch as f32 / 2.0, patch as f32 / 4.0) {
            if let Some(node) = candidates::describe(f, w, h, c, &g.exits_in(&idx, c, r), r, 0.02) {
                out.push(UserPatch { kind, node });
            }
        }
        graphs.push(g);
    }
    let valleys = graphs.pop().expect("two graphs");
    let ridges = graphs.pop().expect("two graphs");
    (ridges, valleys, out)
}
