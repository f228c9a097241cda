//! The editor's limits, over real sockets on 127.0.0.1: loopback only,
//! other host names and sites refused, bodies and sessions bounded (by
//! count and by memory), malformed paths, and a property test that no
//! request body, however mangled, gets a 5xx or stops the server. (The
//! endpoints themselves: `tests/serve/api.rs`.)
use crate::common::editor::{N, create, doc, expect_error, put_scene, serve, serve_with};
use crate::common::http;
use proptest::prelude::*;
use serde_json::{Value, json};
use std::net::SocketAddr;
use std::time::Duration;
use terrasynth::server::{self, Config, ServeError};

#[test]
fn only_loopback_addresses_are_served() {
    for bind in ["0.0.0.0:0", "[::]:0", "192.0.2.1:0"] {
        let bind: SocketAddr = bind.parse().unwrap();
        match server::start(Config {
            bind,
            ..Config::default()
        }) {
            Err(e @ ServeError::NotLoopback(_)) => {
                assert!(e.to_string().contains("loopback only"), "{e}")
            }
            Err(e) => panic!("{bind}: {e}"),
            Ok(_) => panic!("{bind} was served"),
        }
    }
}

#[test]
fn malformed_paths_and_sizes_beyond_memory_are_refused() {
    let s = serve(N, None, 2);
    let a = s.addr;
    let (id, _) = create(a);
    // Session ids that are not UTF-8, or not sessions, name the id.
    expect_error(&http::get(a, "/api/sessions/%FF%FE"), 400, "id");
    expect_error(&http::post(a, "/api/sessions/%C0/undo", None), 400, "id");
    expect_error(&http::post(a, "/api/sessions/nope/undo", None), 404, "id");
    expect_error(
        &http::get(a, "/api/exemplars/%FF/preview.png"),
        400,
        "index",
    );
    expect_error(&http::get(a, "/api/exemplars/-1/preview.png"), 422, "index");
    // A document asking for more memory than the machine has is refused
    // before anything is allocated, and the session goes on.
    if terrasynth::io::available_memory().is_some() {
        let mut huge = doc();
        huge["size"] = json!([32768, 32768]);
        let message = expect_error(&put_scene(a, &id, &huge, true), 503, "$");
        assert!(message.contains("MiB"), "{message}");
        let r = http::post(a, "/api/sessions", Some(&json!({"scene": huge})));
        expect_error(&r, 503, "$");
    } else {
        eprintln!("skipped the memory refusal: no MemAvailable here");
    }
    assert_eq!(put_scene(a, &id, &doc(), true).status, 200);
}

#[test]
fn other_hosts_sites_and_oversized_bodies_are_refused() {
    let s = serve(N, None, 2);
    let a = s.addr;
    let req = |head: &str| {
        http::raw(
            a,
            format!("{head}\r\nConnection: close\r\nContent-Length: 0\r\n\r\n").as_bytes(),
        )
    };
    expect_error(
        &req("GET /api/info HTTP/1.1\r\nHost: evil.example:80"),
        403,
        "$",
    );
    expect_error(
        &req(&format!(
            "POST /api/sessions HTTP/1.1\r\nHost: {a}\r\nOrigin: http://evil.example"
        )),
        403,
        "$",
    );
    // Same-origin pages may.
    let ok = req(&format!(
        "POST /api/sessions HTTP/1.1\r\nHost: {a}\r\nOrigin: http://{a}"
    ));
    assert_eq!(ok.status, 200);
    let (id, _) = create(a);
    let big = vec![b' '; 17 << 20];
    let r = http::request(
        a,
        "PUT",
        &format!("/api/sessions/{id}/scene"),
        Some(&big),
        None,
    );
    expect_error(&r, 413, "$");
}

/// A tab that stopped pinging (a crashed browser, a page reloaded before
/// it learnt its session's id) gives its slot to the next tab within the
/// idle time; one that pings keeps it. The heartbeat the page should keep
/// is in /api/info.
#[test]
fn a_silent_session_gives_its_slot_up() {
    let s = serve_with(N, None, |c| {
        c.max_sessions = 2;
        c.idle = Duration::from_millis(600);
    });
    let a = s.addr;
    let info = http::get(a, "/api/info").json();
    assert_eq!(info["sessions"]["heartbeat_ms"], 150, "{info}");
    let (pinged, _) = create(a);
    let (silent, _) = create(a);
    expect_error(&http::post(a, "/api/sessions", None), 503, "$");
    for _ in 0..8 {
        std::thread::sleep(Duration::from_millis(100));
        let r = http::post(a, &format!("/api/sessions/{pinged}/ping"), None);
        assert_eq!(r.json(), serde_json::json!({"stale": false}));
    }
    let (third, _) = create(a);
    expect_error(&http::get(a, &format!("/api/sessions/{silent}")), 404, "id");
    for id in [&pinged, &third] {
        assert_eq!(http::get(a, &format!("/api/sessions/{id}")).status, 200);
    }
}

#[test]
fn tabs_get_their_own_sessions_up_to_the_limit() {
    let s = serve(N, None, 2);
    let a = s.addr;
    let (one, _) = create(a);
    let (two, _) = create(a);
    assert_ne!(one, two);
    let mut d = doc();
    d["points"] = json!([{"at": [20, 20], "height_m": 2500, "radius_px": 6}]);
    put_scene(a, &one, &d, true);
    // The other tab's session did not see that edit.
    assert_eq!(
        http::get(a, &format!("/api/sessions/{two}")).json()["scene"],
        doc()
    );
    let third = expect_error(&http::post(a, "/api/sessions", None), 503, "$");
    assert!(third.contains("--max-sessions"), "{third}");
    assert_eq!(
        http::post(a, &format!("/api/sessions/{two}/close"), None).status,
        204
    );
    expect_error(&http::get(a, &format!("/api/sessions/{two}")), 404, "id");
    assert_eq!(http::post(a, "/api/sessions", None).status, 200);
    assert_eq!(
        http::post(a, &format!("/api/sessions/{one}/ping"), None).status,
        200
    );
    // A body for a new session: {"scene": …}, with the document's paths.
    let mut bad = doc();
    bad["seed"] = json!(-1);
    http::post(a, &format!("/api/sessions/{one}/close"), None);
    expect_error(
        &http::post(a, "/api/sessions", Some(&json!({"scene": bad}))),
        422,
        "seed",
    );
    expect_error(
        &http::post(a, "/api/sessions", Some(&json!({"scène": doc()}))),
        400,
        "scène",
    );
}

/// The editor_request fuzz target's seeds, replayed as the target runs
/// them: each parses or is refused with an error naming a field.
#[test]
fn fuzz_seeds_of_the_request_parsers_replay() {
    use terrasynth::server::api::request;
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/corpus/editor_request");
    let mut n = 0;
    for entry in std::fs::read_dir(dir).unwrap() {
        let data = std::fs::read(entry.unwrap().path()).unwrap();
        let (&which, rest) = data.split_first().unwrap();
        let field = match which % 3 {
            0 => request::view(rest).err(),
            1 => request::new_session(rest).err(),
            _ => {
                let q = request::query(
                    Some(std::str::from_utf8(rest).unwrap()),
                    &["commit", "format", "sidecar", "revision"],
                );
                q.and_then(|p| request::flag(&p, "commit", true).and(request::revision(&p)))
                    .err()
            }
        }
        .map(|e| e.field().to_string());
        assert!(field.is_none_or(|f| !f.is_empty()));
        n += 1;
    }
    assert!(n >= 6, "{n} seeds");
    // The seeds' refusals name what was wrong.
    assert_eq!(
        request::view(br#"{"contours": 1}"#).unwrap_err().field(),
        "contours"
    );
    assert_eq!(
        request::new_session(br#"{"sc\u00e8ne": 1}"#)
            .unwrap_err()
            .field(),
        "scène"
    );
    let q = request::query(
        Some("commit=maybe&&=&revision=-1&revision=2"),
        &["commit", "revision"],
    )
    .unwrap_err();
    assert_eq!(q.field(), "$");
}

/// Values that do not belong in a scene document.
fn junk() -> impl Strategy<Value = Value> {
    prop_oneof![
        Just(Value::Null),
        any::<bool>().prop_map(Value::from),
        any::<i64>().prop_map(Value::from),
        any::<f64>()
            .prop_map(|f| serde_json::Number::from_f64(f).map_or(Value::Null, Value::Number)),
        "[a-z\\[\\]\\.]{0,12}".prop_map(Value::from),
        Just(json!([])),
        Just(json!({})),
        Just(json!([[1e9, -3]])),
    ]
}

/// A rich document, mangled at one JSON path.
fn mangled() -> impl Strategy<Value = Vec<u8>> {
    let base = json!({
        "version": 1, "size": [N, N], "seed": 3,
        "points": [{"id": "p", "at": [20, 20], "height_m": 900, "slope_deg": 10, "radius_px": 6}],
        "curves": [{"points": [[5, 40], [30, 45], [60, 40]], "smoothing": 2,
                    "widgets": [{"at": 0.5, "height_m": 700, "slope_deg": [20, 20], "reach_px": [8, 8]}]}],
        "types": {"strokes": [{"type": "hills", "points": [[10, 10], [20, 12]], "radius_px": 4}]},
        "freeze": {"strokes": [{"points": [[50, 10]], "radius_px": 3}]},
    });
    let paths = [
        "/size",
        "/size/0",
        "/seed",
        "/points",
        "/points/0",
        "/points/0/at",
        "/points/0/at/1",
        "/points/0/radius_px",
        "/points/0/height_m",
        "/curves/0/points",
        "/curves/0/points/1",
        "/curves/0/widgets/0/reach_px",
        "/curves/0/widgets/0/at",
        "/curves/0/smoothing",
        "/types",
        "/types/strokes/0/type",
        "/types/strokes/0/radius_px",
        "/freeze/strokes/0",
        "/freeze/strokes/0/points",
        "/version",
    ];
    prop_oneof![
        (0..paths.len(), junk()).prop_map(move |(i, v)| {
            let mut d = base.clone();
            if let Some(slot) = d.pointer_mut(paths[i]) {
                *slot = v;
            }
            d.to_string().into_bytes()
        }),
        proptest::collection::vec(any::<u8>(), 0..200),
        (any::<u16>(), any::<u8>()).prop_map(|(at, b)| {
            let mut s = json!({"size": [N, N], "seed": 1}).to_string().into_bytes();
            let k = at as usize % s.len();
            s[k] = b;
            s
        }),
    ]
}

proptest! {
    #![proptest_config(crate::common::proptest_cases(96))]

    /// Whatever the body, the answer is a frame or a 4xx JSON error naming
    /// a field, and the server keeps serving.
    #[test]
    fn mangled_requests_get_4xx_never_5xx(body in mangled(), endpoint in 0usize..3) {
        use std::sync::OnceLock;
        static SERVER: OnceLock<(terrasynth::server::Running, String)> = OnceLock::new();
        let (server, id) = SERVER.get_or_init(|| {
            let s = serve(N, None, 4);
            let (id, _) = create(s.addr);
            (s, id)
        });
        let a = server.addr;
        let path = match endpoint {
            0 => format!("/api/sessions/{id}/scene?commit=false"),
            1 => format!("/api/sessions/{id}/view"),
            _ => "/api/sessions".to_string(),
        };
        let method = if endpoint == 2 { "POST" } else { "PUT" };
        let r = http::request(a, method, &path, Some(&body), None);
        prop_assert!(r.status == 200 || (400..500).contains(&r.status), "{} for {}", r.status, String::from_utf8_lossy(&body));
        if r.status != 200 {
            let v = r.json();
            prop_assert!(v["error"]["field"].is_string(), "{v}");
        } else if endpoint == 2 {
            // A new session was made from the body: free its slot.
            let sid = r.json()["session"].as_str().unwrap().to_string();
            http::post(a, &format!("/api/sessions/{sid}/close"), None);
        }
        prop_assert_eq!(http::get(a, "/api/info").status, 200);
    }
}
