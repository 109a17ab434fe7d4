"""The ``meshmark`` command: serve a map in the browser, or inspect and convert files headless."""

from __future__ import annotations

import argparse
import logging
import sys
import time
from collections.abc import Sequence
from pathlib import Path

from app import labels_cli, layers_cli
from storage import MeshmarkError

logger = logging.getLogger("meshmark")


def main(argv: Sequence[str] | None = None) -> int:
    """Run the ``meshmark`` command line; return the process exit code."""
    parser = _parser()
    args = parser.parse_args(argv)
    logging.basicConfig(
        level=logging.DEBUG if getattr(args, "verbose", False) else logging.INFO,
        format="%(asctime)s %(levelname)s %(name)s: %(message)s",
    )
    try:
        return int(args.run(args) or 0)
    except MeshmarkError as exc:
        print(f"meshmark: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        return 130


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="meshmark", description="Annotate robot mesh maps in the browser."
    )
    sub = parser.add_subparsers(dest="command", required=True)

    serve = sub.add_parser("serve", help="open a map in the browser (default: the demo map)")
    serve.add_argument("path", nargs="?", type=Path, help="map to open (.h5 .ply .obj .glb .stl)")
    serve.add_argument("--host", default="127.0.0.1", help="address to bind (default 127.0.0.1)")
    serve.add_argument("--port", type=int, default=8080)
    serve.add_argument(
        "--data-dir",
        type=Path,
        default=Path.cwd(),
        help="folder the browser may open and save in (default: the current directory)",
    )
    serve.add_argument("--max-upload-mb", type=float, default=512.0)
    serve.add_argument("-v", "--verbose", action="store_true")
    serve.set_defaults(run=_serve)

    info = sub.add_parser("info", help="print what a map file holds")
    info.add_argument("path", type=Path)
    info.set_defaults(run=_info)

    convert = sub.add_parser("convert", help="write any map or mesh in the current HDF5 layout")
    convert.add_argument("source", type=Path)
    convert.add_argument("target", type=Path)
    convert.add_argument(
        "--compression", choices=("gzip", "none"), default="gzip", help="default: gzip"
    )
    convert.set_defaults(run=_convert)

    goals = sub.add_parser("goals", help="print the goal poses saved in a map")
    goals.add_argument("path", type=Path)
    goals.add_argument("--format", choices=("yaml", "json"), default="yaml")
    goals.set_defaults(run=_goals)
    layers_cli.add_parser(sub)
    labels_cli.add_parser(sub)
    return parser


def _serve(args: argparse.Namespace) -> int:
    import viser

    from app.server import MeshmarkApp
    from static import demo_map_path
    from storage import load_map

    path = args.path if args.path is not None else demo_map_path()
    doc = load_map(path)
    for warning in doc.warnings:
        logger.warning("%s: %s", path.name, warning)
    server = viser.ViserServer(host=args.host, port=args.port, verbose=False)
    server.gui.set_panel_label("meshmark")
    app = MeshmarkApp(server, doc, data_dir=args.data_dir, max_upload_mb=args.max_upload_mb)
    host = "127.0.0.1" if args.host in ("0.0.0.0", "") else args.host
    print(f"meshmark: serving {path.name} at http://{host}:{server.get_port()}/", flush=True)
    try:
        while True:
            time.sleep(3600)
    finally:
        app.close()
        server.stop()


def _info(args: argparse.Namespace) -> int:
    from storage import inspect_map

    print(inspect_map(args.path).to_text())
    return 0


def _convert(args: argparse.Namespace) -> int:
    from storage import load_map, save_map

    doc = load_map(args.source)
    for warning in doc.warnings:
        print(f"meshmark: {args.source.name}: {warning}", file=sys.stderr)
    compression = None if args.compression == "none" else args.compression
    save_map(doc, args.target, compression=compression)
    print(f"meshmark: wrote {args.target} ({doc.n_vertices:,} vertices, {doc.n_faces:,} faces)")
    return 0


def _goals(args: argparse.Namespace) -> int:
    from storage import goals_to_json, goals_to_yaml, load_map

    doc = load_map(args.path)
    write = goals_to_yaml if args.format == "yaml" else goals_to_json
    origin = doc.origin if doc.origin.any() else None
    sys.stdout.write(write(list(doc.goals), origin=origin))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
