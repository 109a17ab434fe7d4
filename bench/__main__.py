"""Run every benchmark group on one synthetic terrain and write one JSON object.

python -m bench --faces 1000000 --out bench.json [--only storage,selection] [--utm]
"""

from __future__ import annotations

import argparse
import importlib
import json
import resource
import sys
import time

from bench.terrain import make_terrain

#: group name -> module with ``run(terrain, args) -> dict``; imported lazily.
GROUPS = {
    "storage": "bench.storage_bench",
    "selection": "bench.selection_bench",
    "layers": "bench.layers_bench",
    "labels": "bench.labels_bench",
}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m bench", description=__doc__)
    parser.add_argument("--faces", type=int, default=1_000_000)
    parser.add_argument("--out", default="bench.json")
    parser.add_argument("--only", default="", help="comma-separated groups: " + ",".join(GROUPS))
    parser.add_argument("--utm", action="store_true", help="shift the terrain to UTM coordinates")
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args(argv)
    chosen = [g for g in args.only.split(",") if g] or list(GROUPS)
    unknown = set(chosen) - set(GROUPS)
    if unknown:
        parser.error(f"unknown groups: {', '.join(sorted(unknown))}")
    terrain = make_terrain(args.faces, utm=args.utm)
    result: dict[str, object] = {
        "faces": terrain.n_faces,
        "vertices": len(terrain.vertices),
        "utm": args.utm,
        "repeats": args.repeats,
    }
    for group in chosen:
        try:
            module = importlib.import_module(GROUPS[group])
        except ModuleNotFoundError as exc:
            if exc.name != GROUPS[group]:
                raise
            print(f"[bench] group {group!r} is not available yet", file=sys.stderr)
            continue
        t0 = time.perf_counter()
        result.update(module.run(terrain, args))
        print(f"[bench] {group}: {time.perf_counter() - t0:.1f} s", file=sys.stderr)
    result["peak_rss_mb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    with open(args.out, "w") as fh:
        json.dump(result, fh, indent=2)
    width = max(len(k) for k in result)
    for key, value in result.items():
        shown = f"{value:.4g}" if isinstance(value, float) else value
        print(f"{key:<{width}}  {shown}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
