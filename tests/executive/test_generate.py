"""delve.executive.generate: the generated files go where they are told, and nowhere else."""
from __future__ import annotations

from delve.executive import generate, node_docs, tree_schema


def test_writes_the_schema_and_the_reference_to_the_paths_given(tmp_path, capsys):
    out = tmp_path / "out"
    assert generate.main(["--schema-dir", str(out / "schema"), "--docs", str(out / "doc" / "nodes.md")]) == 0
    written = sorted(p.relative_to(out).as_posix() for p in out.rglob("*") if p.is_file())
    assert written == ["doc/nodes.md", "schema/tree.schema.json"]
    assert (out / "schema" / "tree.schema.json").read_text(encoding="utf-8") == tree_schema.schema_text()
    assert (out / "doc" / "nodes.md").read_text(encoding="utf-8") == node_docs.reference_markdown()
    assert "Sequence [composite]" not in capsys.readouterr().out


def test_without_paths_it_lists_and_writes_nothing(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert generate.main([]) == 0
    assert "Sequence [composite] (children)" in capsys.readouterr().out
    assert list(tmp_path.iterdir()) == []
