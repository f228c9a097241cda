//! Editing on the embedded default database at 1024²: one moved point
//! constraint re-synthesized coherently (`edit/cpu/1024/moved_point`:
//! restricted to the region that can change, byte-identical to the full
//! re-synthesis; `edit/cpu/1024/moved_point_full`: every pixel corrected)
//! against a full synthesis without controls (`edit/cpu/1024/full_synthesis`);
//! with `--features gpu` and an adapter, the moved point on the GPU too
//! (`edit/gpu/1024/moved_point`).
//! Issue 5's target: the edit in ≤ 50% of the full time; issue 18's: the
//! moved point in ≤ 30 ms on 2 cores.

use criterion::{Criterion, criterion_group, criterion_main};
use std::sync::Arc;
use terrasynth::database::default;
use terrasynth::progress::Silent;
use terrasynth::synth::control::{ConstraintId, PointConstraint};
use terrasynth::synth::session::{Edit, Session};
use terrasynth::synth::{Params, Synthesizer};

const N: usize = 1024;

fn bench(c: &mut Criterion) {
    let db = default::build_default(&Silent).unwrap();
    let cell = db.meta().exemplars[0].cell_size_m;
    let q = db.quantization();
    let height = q.metres(40_000.0);
    let point = |x: f64| -> Edit {
        let p = PointConstraint::new((x, 500.0), height, 0.4, 0.3, 48.0, cell).unwrap();
        Edit::SetConstraint(ConstraintId(0), Arc::new(p))
    };
    let mut g = c.benchmark_group("edit");
    g.sample_size(10);
    // Back and forth by 20 px: every iteration moves the point.
    let mut moves = |name: &str, mut s: Session<'_>| {
        s.apply(vec![point(400.0)]).unwrap();
        s.apply(vec![point(420.0)]).unwrap();
        let mut k = 0;
        g.bench_function(name, |b| {
            b.iter(|| {
                k += 1;
                s.apply(vec![point(if k % 2 == 0 { 420.0 } else { 400.0 })])
                    .unwrap()
            })
        });
    };
    for (name, restrict) in [
        ("cpu/1024/moved_point", true),
        ("cpu/1024/moved_point_full", false),
    ] {
        let mut s = Session::new(&db, Params::default(), N, N, 1).unwrap();
        s.restrict = restrict;
        moves(name, s);
    }
    #[cfg(feature = "gpu")]
    {
        let mut s = Session::new(&db, Params::default(), N, N, 1).unwrap();
        match s
            .synthesizer_mut()
            .use_backend(terrasynth::backend::Choice::Gpu)
        {
            Ok(_) => moves("gpu/1024/moved_point", s),
            Err(e) => eprintln!("edit/gpu: skipped, no GPU adapter ({e})"),
        }
    }
    let synth = Synthesizer::new(&db, Params::default()).unwrap();
    g.bench_function("cpu/1024/full_synthesis", |b| {
        b.iter(|| synth.synthesize(N, N, 1).unwrap())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
