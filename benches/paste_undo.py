#!/usr/bin/env python3
"""Server time of a lasso paste, its undo and its redo in `terrasynth serve`
(issue 43 item 3: undo of a paste rebuilt the whole session).

    python3 benches/paste_undo.py BINARY SIZE [REPS] [point]

Starts BINARY serve at SIZE² (seed 1, embedded database), opens a session,
and REPS times pastes a terrain lasso (each at another place, so no kept
state matches it), undoes it and redoes it, then undoes it again. Prints
the medians of the server's own `timing_ms.total` (queue wait excluded)
and whether the session was rebuilt or a kept state restored. With
`point`, the design has a point constraint (its sums are part of a kept
state).
"""
import json, os, socket, statistics, subprocess, sys, tempfile, time, urllib.request

binary, size = sys.argv[1], int(sys.argv[2])
reps = int(sys.argv[3]) if len(sys.argv) > 3 else 7
with socket.socket() as s:
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
cache = os.environ.get("TERRASYNTH_CACHE_DIR", os.path.join(tempfile.gettempdir(), "terrasynth-bench-cache"))
env = dict(os.environ, TERRASYNTH_CACHE_DIR=cache)
server = subprocess.Popen([binary, "serve", "--bind", f"127.0.0.1:{port}", "--size", f"{size}x{size}", "--seed", "1"],
                          env=env, stderr=subprocess.DEVNULL)
base = f"http://127.0.0.1:{port}"


def call(method, path, body=None):
    data = None if body is None else json.dumps(body).encode()
    req = urllib.request.Request(base + path, data=data, method=method, headers={"content-type": "application/json"})
    with urllib.request.urlopen(req, timeout=600) as r:
        return json.loads(r.read())


try:
    for _ in range(600):
        try:
            if call("GET", "/api/info")["status"] == "ready":
                break
        except OSError:
            pass
        time.sleep(0.5)
    first = call("POST", "/api/sessions")
    sid, doc = first["session"], first["scene"]
    s = size / 1024
    if "point" in sys.argv[4:]:
        doc = dict(doc, points=[{"at": [800 * s, 200 * s], "height_m": 900, "radius_px": 40 * s}])
        call("PUT", f"/api/sessions/{sid}/scene?commit=true", doc)
    lasso = [[100 * s, 100 * s], [300 * s, 120 * s], [260 * s, 320 * s], [120 * s, 280 * s]]
    times = {"paste": [], "undo": [], "redo": []}
    how = {"undo": set(), "redo": set()}
    for k in range(reps):
        d = dict(doc, pastes=[{"source": "terrain", "lasso": lasso, "to": [600 * s + 4 * k, 600 * s]}])
        f = call("PUT", f"/api/sessions/{sid}/scene?commit=true", d)
        times["paste"].append(f["timing_ms"]["total"])
        for what in ("undo", "redo"):
            f = call("POST", f"/api/sessions/{sid}/{what}")
            times[what].append(f["timing_ms"]["total"])
            how[what].add("rebuilt" if f.get("rebuilt") else "restored" if f.get("restored") else "edit")
        call("POST", f"/api/sessions/{sid}/undo")
    kept = call("GET", f"/api/sessions/{sid}").get("checkpoint_bytes")
    print(json.dumps({"size": size, "reps": reps,
                      "median_ms": {k: statistics.median(v) for k, v in times.items()},
                      "all_ms": times, "how": {k: sorted(v) for k, v in how.items()},
                      "checkpoint_bytes": kept}))
finally:
    server.terminate()
    server.wait()
