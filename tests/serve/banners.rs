//! The messages the editor's page shows over the map: server unreachable
//! (`web/js/link.js`), work recovered from an autosave (`main.js`) and a
//! stale save (`save.js`), in one column (`#banners` in `web/index.html`).
use crate::common::browser::{executables, in_chromium, js, settled};
use crate::common::editor;

/// The messages over the map — server unreachable, work recovered from an
/// autosave, a stale save — can be up at once (a tab that saved late
/// while the server restarts). Shown together, each is whole and none
/// covers another (they were all pinned to one place, each hiding the
/// one below it).
#[test]
fn banners_stack_without_hiding_each_other() {
    let Some(browser) = executables() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let server = editor::serve(64, None, 2);
    in_chromium(&browser, dir.path(), async |c| {
        c.goto(&server.url()).await.unwrap();
        settled(c, -1).await;
        let rects = js(
            c,
            "return ['offline', 'recovery', 'conflict'].map(id => {
               const e = document.getElementById(id);
               e.hidden = false;
               (e.querySelector('span') || e).textContent = 'a message as long as a real one, for ' + id;
               const b = e.getBoundingClientRect();
               return [b.left, b.top, b.right, b.bottom];
             });",
        )
        .await;
        let r: Vec<[f64; 4]> = serde_json::from_value(rects).unwrap();
        let (w, h) = {
            let v = js(c, "return [window.innerWidth, window.innerHeight]").await;
            (v[0].as_f64().unwrap(), v[1].as_f64().unwrap())
        };
        for (i, a) in r.iter().enumerate() {
            assert!(
                a[2] - a[0] > 50.0
                    && a[3] - a[1] > 10.0
                    && a[0] >= 0.0
                    && a[1] >= 0.0
                    && a[2] <= w
                    && a[3] <= h,
                "banner {i} {a:?} is not whole in the {w}×{h} window"
            );
            for (j, b) in r.iter().enumerate().skip(i + 1) {
                let apart = a[2] <= b[0] || b[2] <= a[0] || a[3] <= b[1] || b[3] <= a[1];
                assert!(apart, "banners {i} {a:?} and {j} {b:?} overlap");
            }
        }
    });
    server.stop();
}
