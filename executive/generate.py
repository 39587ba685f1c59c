"""Write the files generated from the node registry to the paths given.

    python -m delve.executive.generate --schema-dir executive/schema --docs docs/nodes.md

writes ``tree.schema.json`` into ``--schema-dir`` and the node reference to ``--docs``
(``make docs`` passes the source tree's paths). Nothing is written to a default place,
so an installed package never writes into its own folder. ``--list`` (the default when
nothing is to be written) prints the node types and their parameters.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from .node_docs import describe, reference_markdown
from .tree_schema import SCHEMA_FILE_NAME, schema_text

__all__ = ["main", "write_docs", "write_schema"]


def _write(path: Path, text: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text, encoding="utf-8")
    return path


def write_schema(schema_dir: Path) -> Path:
    """Write the tree schema into ``schema_dir``; return the file written."""
    return _write(Path(schema_dir) / SCHEMA_FILE_NAME, schema_text())


def write_docs(path: Path) -> Path:
    """Write the node reference (Markdown) to ``path``; return it."""
    return _write(Path(path), reference_markdown())


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m delve.executive.generate", description=__doc__.split("\n")[0])
    parser.add_argument("--schema-dir", type=Path, metavar="DIR", help=f"write {SCHEMA_FILE_NAME} into DIR")
    parser.add_argument("--docs", type=Path, metavar="FILE", help="write the node reference (Markdown) to FILE")
    parser.add_argument("--list", action="store_true", help="list node types and their parameters")
    args = parser.parse_args(argv)
    if args.schema_dir is not None:
        print(f"wrote {write_schema(args.schema_dir)}")
    if args.docs is not None:
        print(f"wrote {write_docs(args.docs)}")
    if args.list or (args.schema_dir is None and args.docs is None):
        print(describe())
    return 0


if __name__ == "__main__":
    sys.exit(main())
