//! PPA and the feature graph on constructed sketches (issue 7 "Done means"):
//! a Y-branch and Zhou's λ inside a circle give the right trees.

use proptest::prelude::*;
use std::path::Path;
use terrasynth::patch::input::graph::FeatureGraph;
use terrasynth::patch::input::ppa;
use terrasynth::patch::input::sketch::{Kind, Sketch, Stroke};
use terrasynth::patch::{sketch_field, sketch_graph, sketch_ppa_params};

const PATCH: usize = 64;

/// Ridges of a sketch at `size`, as the synthesis sees them.
fn ridge_graph(sketch: &Sketch, size: usize) -> (ppa::Tree, FeatureGraph) {
    let field = sketch_field(sketch, size, size, PATCH);
    sketch_graph(&field, size, size, PATCH, Kind::Ridge)
}

fn dist(a: [f32; 2], b: [f32; 2]) -> f32 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt()
}

/// Checks forest-ness: edges = nodes − components, for the pixel tree and
/// for the graph of key nodes and paths.
fn assert_acyclic(tree: &ppa::Tree, g: &FeatureGraph) {
    assert_eq!(
        tree.edge_count(),
        tree.pos.len() - tree.components(),
        "pixel tree has a cycle"
    );
    // Components of the key-node graph.
    let m = g.nodes.len();
    let mut parent: Vec<usize> = (0..m).collect();
    fn find(p: &mut [usize], mut a: usize) -> usize {
        while p[a] != a {
            a = p[a];
        }
        a
    }
    for p in &g.paths {
        let (a, b) = (find(&mut parent, p.a), find(&mut parent, p.b));
        assert_ne!(a, b, "path {}–{} closes a cycle", p.a, p.b);
        parent[a] = b;
    }
}

fn stroke(kind: Kind, pts: &[[f32; 2]]) -> Stroke {
    Stroke {
        kind,
        width: 14.0,
        points: pts.to_vec(),
    }
}

#[test]
fn a_y_branch_gives_one_branch_point_and_three_endpoints() {
    let c = [256.0, 280.0];
    let ends = [[110.0, 80.0], [410.0, 80.0], [256.0, 470.0]];
    let sketch = Sketch::Strokes {
        width: 512,
        height: 512,
        strokes: ends.iter().map(|&e| stroke(Kind::Ridge, &[c, e])).collect(),
    };
    let (tree, g) = ridge_graph(&sketch, 512);
    assert_acyclic(&tree, &g);
    let deg = g.degrees();
    let branches: Vec<usize> = (0..deg.len()).filter(|&i| deg[i] >= 3).collect();
    let leaves: Vec<usize> = (0..deg.len()).filter(|&i| deg[i] == 1).collect();
    assert_eq!(branches.len(), 1, "degrees {deg:?}");
    assert_eq!(deg[branches[0]], 3);
    assert_eq!(leaves.len(), 3, "degrees {deg:?}");
    assert_eq!(g.paths.len(), 3);
    assert!(
        dist(g.nodes[branches[0]], c) < 10.0,
        "branch at {:?}",
        g.nodes[branches[0]]
    );
    for e in ends {
        let near = leaves
            .iter()
            .map(|&l| dist(g.nodes[l], e))
            .fold(f32::INFINITY, f32::min);
        assert!(near < 24.0, "no endpoint near {e:?} (nearest {near})");
    }
    // Control points: 3 at the branch, 2 in the middle of an arm, 1 at an end.
    let r = PATCH as f32 / 4.0;
    assert_eq!(g.exits(g.nodes[branches[0]], r).len(), 3);
    assert_eq!(g.exits([183.0, 180.0], r).len(), 2);
    assert_eq!(g.exits(g.nodes[leaves[0]], r).len(), 1);
}

#[test]
fn lambda_in_a_circle_gives_a_branched_lambda_and_a_broken_circle() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/sketches/lambda_circle.json");
    let sketch = Sketch::read(&path).unwrap();
    let (tree, g) = ridge_graph(&sketch, 512);
    assert_acyclic(&tree, &g);
    assert_eq!(tree.components(), 2, "λ and circle");
    let deg = g.degrees();
    let mut hist = [0usize; 5];
    for &d in &deg {
        hist[d.min(4)] += 1;
    }
    // λ: one degree-3 branch point and 3 endpoints; the circle, broken by
    // the spanning forest, is one path with 2 endpoints.
    assert_eq!(hist[3], 1, "degrees {deg:?}");
    assert_eq!(hist[4], 0, "degrees {deg:?}");
    assert_eq!(hist[1], 5, "degrees {deg:?}");
    let b = (0..deg.len()).find(|&i| deg[i] == 3).unwrap();
    assert!(
        dist(g.nodes[b], [256.0, 256.0]) < 16.0,
        "branch at {:?}",
        g.nodes[b]
    );
    // The circle's two ends are next to each other: one short gap where the
    // spanning forest broke the loop (ends may retreat by about a stroke width).
    let circle_ends: Vec<[f32; 2]> = (0..deg.len())
        .filter(|&i| deg[i] == 1 && (dist(g.nodes[i], [256.0, 256.0]) - 210.0).abs() < 12.0)
        .map(|i| g.nodes[i])
        .collect();
    assert_eq!(circle_ends.len(), 2, "{circle_ends:?}");
    assert!(
        dist(circle_ends[0], circle_ends[1]) < 24.0,
        "{circle_ends:?}"
    );
    // Breadth-first placement starts at the branch point.
    let places = g.placements(PATCH as f32 / 2.0, PATCH as f32 / 4.0);
    assert!(dist(places[0], g.nodes[b]) < 1e-3);
    assert!(
        places.len() >= 40,
        "{} patches for a 2·π·210 + λ sketch",
        places.len()
    );
}

proptest! {
    #![proptest_config(crate::common::proptest_cases(24))]
    /// Whatever is sketched, PPA's output is a forest.
    #[test]
    fn any_sketch_gives_a_forest(
        strokes in prop::collection::vec(
            (prop::bool::ANY, prop::collection::vec((0.0f32..128.0, 0.0f32..128.0), 1..5), 3.0f32..20.0),
            1..5,
        )
    ) {
        let sketch = Sketch::Strokes {
            width: 128,
            height: 128,
            strokes: strokes
                .iter()
                .map(|(r, pts, w)| Stroke {
                    kind: if *r { Kind::Ridge } else { Kind::Valley },
                    width: *w,
                    points: pts.iter().map(|&(x, y)| [x, y]).collect(),
                })
                .collect(),
        };
        for sign in [1.0f32, -1.0] {
            let field: Vec<f32> = sketch_field(&sketch, 128, 128, 32).iter().map(|v| v * sign).collect();
            let tree = ppa::extract(128, 128, &field, &sketch_ppa_params(32));
            prop_assert_eq!(tree.edge_count(), tree.pos.len() - tree.components());
            let g = FeatureGraph::from_tree(&tree, 4.0);
            prop_assert!(g.paths.len() < g.nodes.len().max(1) || g.nodes.is_empty());
            assert_acyclic(&tree, &g);
        }
    }
}
