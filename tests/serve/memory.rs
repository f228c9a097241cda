//! What the editor's server holds as a session is edited (issue 43: undo
//! kept the whole document per step, ~9× its JSON, +6.8 MiB per step for
//! a 0.74 MB scene). On a ~0.7 MB scene: a step of a typical edit (a point
//! moved) must hold under 1 MiB of undo history, and the resident memory
//! of a `terrasynth serve` process after 200 such edits must stay within
//! twice its resident memory after the first (read from /proc/PID/status).
use crate::common::editor::{self, N, create_with, doc, put_scene, serve};
use crate::common::http;
use serde_json::{Value, json};
use std::ffi::OsStr;
use std::time::{Duration, Instant};

/// A ~0.7 MB scene: 3600 short freeze strokes over the lower half of the
/// map, and one point that the edits move.
fn big_scene() -> Value {
    let mut d = doc();
    let strokes: Vec<Value> = (0..3600)
        .map(|k| {
            let y = 40.0 + (k % 20) as f64 + (k / 20) as f64 * 1e-3;
            let line: Vec<Value> = (0..12).map(|i| json!([2.5 + 5.0 * i as f64, y])).collect();
            json!({"points": line, "radius_px": 0.5})
        })
        .collect();
    d["freeze"] = json!({ "strokes": strokes });
    let size = d.to_string().len();
    assert!((600_000..800_000).contains(&size), "{size} B");
    d
}

/// `d` with its point moved to the `k`th place: a typical edit.
fn moved(d: &mut Value, k: usize) {
    d["points"] = json!([{"at": [10 + k % 40, 20], "height_m": 900, "radius_px": 5}]);
}

/// Undo keeps patches, not whole documents: a step of a typical edit (a
/// point moved; a 40-point freeze stroke painted) holds what the edit
/// changed, far under 1 MiB, and undo still gives back each document.
#[test]
fn undo_memory_per_step_is_the_edit_not_the_scene() {
    let s = serve(N, None, 2);
    let a = s.addr;
    let mut d = big_scene();
    let size = d.to_string().len();
    let (id, _) = create_with(a, &d);
    let held = || {
        http::get(a, &format!("/api/sessions/{id}")).json()["history_bytes"]
            .as_u64()
            .unwrap()
    };
    let (mut worst, mut before) = ([0u64; 2], held());
    let steps = 20;
    for k in 0..steps {
        let kind = k % 2;
        if kind == 0 {
            moved(&mut d, k);
        } else {
            let line: Vec<Value> = (0..40)
                .map(|i| json!([1.5 * i as f64, 5.0 + k as f64]))
                .collect();
            d["freeze"]["strokes"]
                .as_array_mut()
                .unwrap()
                .push(json!({"points": line, "radius_px": 1.5}));
        }
        assert_eq!(put_scene(a, &id, &d, true).status, 200);
        let now = held();
        worst[kind] = worst[kind].max(now - before);
        before = now;
    }
    eprintln!(
        "undo history per step on a {size} B scene: {} B for a point moved, {} B for a freeze stroke painted (the most of {steps} steps); {before} B in all",
        worst[0], worst[1]
    );
    assert!(worst.iter().all(|&b| b < 1 << 20), "{worst:?} B per step");
    let u = http::post(a, &format!("/api/sessions/{id}/undo"), None).json();
    d["freeze"]["strokes"].as_array_mut().unwrap().pop();
    assert_eq!(u["scene"], d);
}

/// The resident set of a process, in KiB (`VmRSS` of /proc/PID/status).
fn resident_kib(pid: u32) -> u64 {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).unwrap();
    let line = status.lines().find(|l| l.starts_with("VmRSS:")).unwrap();
    line.split_whitespace().nth(1).unwrap().parse().unwrap()
}

/// 200 edits of the ~0.7 MB scene, each a committed undo step, through a
/// `terrasynth serve` process (with its autosave on): its resident memory
/// after the 200th is at most twice that after the first. Whole documents
/// per step would add ~6 MiB a step, ~1.2 GiB in all.
#[test]
#[cfg(target_os = "linux")]
fn resident_memory_after_200_edits_is_at_most_twice_that_after_one() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("design.json");
    let server = editor::spawn(
        &[OsStr::new("--scene"), scene.as_os_str()],
        &dir.path().join("cache"),
    );
    let a = server.addr;
    let t = Instant::now();
    while http::get(a, "/api/info").json()["status"] != "ready" {
        assert!(
            t.elapsed() < Duration::from_secs(600),
            "the database never loaded"
        );
        std::thread::sleep(Duration::from_millis(100));
    }
    let mut d = big_scene();
    let (id, _) = create_with(a, &d);
    let mut edit = |k: usize| {
        moved(&mut d, k);
        let r = put_scene(a, &id, &d, true);
        assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.body));
    };
    let pid = server.child.id();
    edit(0);
    let one = resident_kib(pid);
    let t = Instant::now();
    for k in 1..200 {
        edit(k);
    }
    let per_edit = t.elapsed().as_secs_f64() * 1e3 / 199.0;
    let two_hundred = resident_kib(pid);
    let history = http::get(a, &format!("/api/sessions/{id}")).json()["history_bytes"].clone();
    eprintln!(
        "server resident: {:.1} MiB after 1 edit, {:.1} MiB after 200 ({:.2}×); undo history {history} B; {per_edit:.0} ms per edit",
        one as f64 / 1024.0,
        two_hundred as f64 / 1024.0,
        two_hundred as f64 / one as f64
    );
    assert!(
        two_hundred <= 2 * one,
        "{two_hundred} KiB after 200 edits, {one} KiB after 1"
    );
}
