"""delve.executive.yamlio: YAML with file and line bookkeeping; errors as DelveError."""
from __future__ import annotations

import math

import pytest
from delve.executive.errors import DelveError, display_path
from delve.executive.yamlio import YamlDict, YamlList, load_yaml, loads_yaml, plain


def write(tmp_path, text, name="x.yaml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_mappings_and_lists_remember_lines(tmp_path):
    path = write(
        tmp_path,
        "# comment\n"
        "a: 1\n"
        "b:\n"
        "  - x\n"
        "  - {c: 2,\n"
        "     d: 3}\n"
        "  - e: 4\n"
        "    f: .nan\n",
    )
    data = load_yaml(path)
    assert isinstance(data, YamlDict) and data.file == str(path)
    assert data.line == 2
    assert data.key_line("a") == 2 and data.key_line("b") == 3
    items = data["b"]
    assert isinstance(items, YamlList) and items.line == 4
    assert [items.item_line(i) for i in range(3)] == [4, 5, 7]
    assert items[1].line == 5 and items[1].key_line("d") == 6
    assert items[2].key_line("f") == 8 and math.isnan(items[2]["f"])
    assert data.key_line("missing") == data.line
    assert items.item_line(99) == items.line


def test_values_are_plain_python(tmp_path):
    data = load_yaml(write(tmp_path, "a: {b: [1, 2.5, true, null, 'x']}\n"))
    assert data == {"a": {"b": [1, 2.5, True, None, "x"]}}
    copied = plain(data)
    assert type(copied) is dict and type(copied["a"]["b"]) is list


def test_merge_keys_may_override(tmp_path):
    data = load_yaml(write(tmp_path, "base: &b {p: 1, q: 2}\nm:\n  <<: *b\n  q: 3\n"))
    assert data["m"] == {"p": 1, "q": 3}
    assert data["m"].key_line("q") == 4


def test_duplicate_key_is_an_error_on_the_second_line(tmp_path):
    path = write(tmp_path, "a: 1\nb:\n  c: 1\n  c: 2\n")
    with pytest.raises(DelveError) as info:
        load_yaml(path)
    assert info.value.line == 4
    assert "duplicate key 'c'" in str(info.value)
    assert str(info.value).startswith(f"{display_path(path)}:4: ")


def test_syntax_error_names_the_line(tmp_path):
    path = write(tmp_path, "a: 1\nb: [1, 2\nc: 3\n")
    with pytest.raises(DelveError) as info:
        load_yaml(path)
    assert info.value.line == 3
    assert "YAML syntax error" in info.value.message


def test_tab_indentation_is_a_syntax_error(tmp_path):
    with pytest.raises(DelveError, match="YAML syntax error"):
        load_yaml(write(tmp_path, "a:\n\tb: 1\n"))


def test_missing_file(tmp_path):
    with pytest.raises(DelveError) as info:
        load_yaml(tmp_path / "nope.yaml")
    assert info.value.message == "file not found"
    assert info.value.line is None
    assert str(info.value).endswith("nope.yaml: file not found")


def test_directory_is_not_a_yaml_file(tmp_path):
    with pytest.raises(DelveError, match="directory"):
        load_yaml(tmp_path)


def test_unhashable_key(tmp_path):
    with pytest.raises(DelveError, match="unhashable"):
        load_yaml(write(tmp_path, "? [1, 2]\n: x\n"))


def test_loads_yaml_and_scalars():
    assert loads_yaml("3") == 3
    assert loads_yaml("") is None
    data = loads_yaml("a: 1\n", file="inline.yaml")
    assert data.file == "inline.yaml" and data.key_line("a") == 1


def test_safe_loader_rejects_python_tags():
    with pytest.raises(DelveError):
        loads_yaml("a: !!python/object/apply:os.system ['true']\n")
