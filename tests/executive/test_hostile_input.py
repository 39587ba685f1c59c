"""Hostile input that is better generated than committed (binary files, huge files,
alias bombs, deep nesting), the include rule, and the command line's one line.

Each case is one line naming file and line, exit status 2, no traceback, and no
more of any file than the offending value's first few dozen characters."""
from __future__ import annotations

import os
import re
import time
from pathlib import Path

import py_trees
import pytest

from delve import TREES_DIR
from delve.executive.cli import main
from delve.executive.errors import DelveError
from delve.executive.render import render_tree
from delve.executive.tree_loader import MAX_TREE_DEPTH, check_context, check_tree, load_tree
from delve.executive.yamlio import MAX_FILE_BYTES, MAX_NESTING_DEPTH, MAX_NODES, load_yaml

DATA = Path(__file__).resolve().parent.parent / "data"


@pytest.fixture(autouse=True)
def clean_blackboard():
    yield
    py_trees.blackboard.Blackboard.clear()


def error_of(path: Path, load=load_yaml) -> DelveError:
    with pytest.raises(DelveError) as info:
        load(path)
    assert type(info.value) is DelveError
    assert "\n" not in str(info.value)
    return info.value


def write(tmp_path: Path, name: str, data: str | bytes) -> Path:
    path = tmp_path / name
    path.parent.mkdir(parents=True, exist_ok=True)
    if isinstance(data, bytes):
        path.write_bytes(data)
    else:
        path.write_text(data)
    return path


# --------------------------------------------------------------------------- characters and encodings


@pytest.mark.parametrize("char, what", [("\x00", "a NUL byte"), ("\x01", "control character U+0001"),
                                        ("\x1b", "control character U+001B"), ("\x7f", "control character U+007F")])
def test_control_characters_and_nul_bytes_name_their_line(tmp_path, char, what):
    path = write(tmp_path, "t.yaml", f"type: Sequence\nchildren:\n  - {{type: Success, name: a{char}b}}\n")
    err = error_of(path)
    assert err.line == 3 and err.message.startswith(what)


@pytest.mark.parametrize("encoding, found", [("utf-16", "UTF-16 (little-endian)"), ("utf-16-be", "UTF-16 (big-endian)"),
                                             ("utf-16-le", "UTF-16 (little-endian)"), ("utf-32", "UTF-32")])
def test_utf16_and_utf32_files_say_which_encoding_they_are(tmp_path, encoding, found):
    text = "type: Sequence\nchildren:\n  - type: Success\n"
    err = error_of(write(tmp_path, "t.yaml", text.encode(encoding)))  # utf-16-le/be: no byte-order mark
    assert found in err.message and "save it as UTF-8" in err.message and err.line == 1


def test_latin1_file_names_the_line_where_decoding_failed(tmp_path):
    path = write(tmp_path, "t.yaml", "type: Sequence\nchildren:\n  - {type: Success, name: Café}\n".encode("latin-1"))
    err = error_of(path)
    assert err.line == 3
    assert "not UTF-8 text: byte 0xe9" in err.message and "Latin-1 or Windows-1252" in err.message


def test_a_utf8_byte_order_mark_is_fine(tmp_path):
    path = write(tmp_path, "t.yaml", "\ufefftype: Success\n".encode("utf-8"))
    assert load_yaml(path) == {"type": "Success"}


# --------------------------------------------------------------------------- sizes, aliases, depth


def test_a_20_mb_file_is_refused_at_once(tmp_path):
    path = tmp_path / "huge.yaml"
    with open(path, "w") as f:
        f.write("type: Sequence\nchildren:\n")
        line = "  - {type: Success, name: " + "x" * 60 + "}\n"
        f.write(line * (20_000_000 // len(line)))
    started = time.process_time()
    err = error_of(path)
    assert time.process_time() - started < 1.0  # refused before parsing (CPU time, not wall time)
    assert err.message == f"file larger than {MAX_FILE_BYTES // 1_000_000} MB: too large for a tree or scenario"


def test_a_file_of_too_many_values_is_refused(tmp_path):
    path = write(tmp_path, "t.yaml", "x: [" + ", ".join(["1"] * (MAX_NODES + 10)) + "]\n")
    assert f"more than {MAX_NODES} values" in error_of(path).message


def test_an_alias_bomb_is_refused_before_it_expands(tmp_path):
    lines = ['a0: &a0 ["lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol"]']
    for i in range(1, 10):
        lines.append(f"a{i}: &a{i} [" + ", ".join([f"*a{i - 1}"] * 9) + "]")
    path = write(tmp_path, "bomb.yaml", "\n".join(lines) + "\ntype: Success\n")
    err = error_of(path)
    assert err.message == f"aliases expand the document to more than {MAX_NODES} values (an alias bomb?)"
    assert 2 <= err.line <= 10


def test_a_merge_key_bomb_is_refused(tmp_path):
    lines = ["b0: &b0 {k0: 1, k1: 2, k2: 3, k3: 4}"]
    for i in range(1, 12):
        lines.append(f"b{i}: &b{i} {{<<: [" + ", ".join([f"*b{i - 1}"] * 6) + f"], own{i}: 1}}")
    err = error_of(write(tmp_path, "merge.yaml", "\n".join(lines) + "\n"))
    assert "alias bomb" in err.message


def test_aliases_within_the_limit_are_fine(tmp_path):
    path = write(tmp_path, "t.yaml", "base: &b {x: 1, y: [1, 2, 3]}\na: *b\nb: *b\nc: {<<: *b, x: 2}\n")
    assert load_yaml(path)["c"] == {"x": 2, "y": [1, 2, 3]}


@pytest.mark.parametrize("text", ["a: &a [1, *a]\n", "a: &a {b: *a}\n", "a: &a\n  - &b [*a]\n"])
def test_recursive_aliases_are_refused(tmp_path, text):
    assert "recursive alias" in error_of(write(tmp_path, "t.yaml", text)).message


def test_thousands_of_brackets_are_refused_at_their_depth(tmp_path):
    path = write(tmp_path, "t.yaml", "type: Success\nx: " + "[" * 5000 + "]" * 5000 + "\n")
    err = error_of(path)
    assert err.message == f"mappings and lists nest more than {MAX_NESTING_DEPTH} deep" and err.line == 2


def decorator_chain(n: int, leaf: str = "type: Success") -> str:
    lines, indent = [], ""
    for _ in range(n):
        lines += [f"{indent}type: Inverter", f"{indent}child:"]
        indent += "  "
    return "\n".join([*lines, indent + leaf]) + "\n"


def test_a_tree_as_deep_as_the_limit_builds_ticks_and_renders(tmp_path):
    path = write(tmp_path, "deep.yaml", decorator_chain(MAX_TREE_DEPTH - 1))
    root = load_tree(path, check_context())
    root.tick_once()
    assert root.status == py_trees.common.Status.FAILURE  # 99 inverters over Success
    render_tree(root, "txt", tmp_path / "deep.txt")
    render_tree(root, "dot", tmp_path / "deep.dot")


def test_a_chain_of_hundreds_of_decorators_is_refused(tmp_path):
    err = error_of(write(tmp_path, "deep.yaml", decorator_chain(600)), check_tree)
    assert f"nest more than {MAX_NESTING_DEPTH} deep" in err.message


def test_a_chain_deeper_than_the_limit_across_includes_is_refused(tmp_path):
    for k in range(12):
        leaf = f"include: c{k + 1}.yaml" if k < 11 else "type: Success"
        write(tmp_path, f"c{k}.yaml", decorator_chain(9, leaf))
    err = error_of(tmp_path / "c0.yaml", check_tree)
    assert err.message == f"the tree nests more than {MAX_TREE_DEPTH} nodes deep (includes counted)"
    assert Path(err.file).name == "c10.yaml"


def test_an_integer_of_thousands_of_digits(tmp_path):
    err = error_of(write(tmp_path, "t.yaml", "type: Timer\nduration_s: " + "7" * 5000 + "\n"))
    assert err.message == "an integer of thousands of digits" and err.line == 2


def test_a_device_is_not_read(tmp_path):
    if not os.path.exists("/dev/zero"):
        pytest.skip("no /dev/zero")
    assert "not a regular file" in error_of(Path("/dev/zero")).message


# --------------------------------------------------------------------------- includes stay home


SECRET = "s3cret-line-that-must-never-be-printed-" * 3


@pytest.fixture
def outside(tmp_path):
    """A folder with a file that trees in the sibling folder ``trees/`` must not read."""
    (tmp_path / "private").mkdir()
    (tmp_path / "private" / "secret.yaml").write_text(f"{SECRET}\n")
    (tmp_path / "private" / "leaf.yaml").write_text("type: Success\n")
    (tmp_path / "trees").mkdir()
    return tmp_path


@pytest.mark.parametrize("target", ["../private/secret.yaml", "{root}/private/secret.yaml",
                                    "../../../../../../../../etc/passwd", "/etc/shadow", "/etc/passwd"])
def test_includes_outside_the_allowed_folders_are_refused_without_reading(outside, target):
    tree = write(outside, "trees/t.yaml", f"type: Sequence\nchildren:\n  - include: {target.format(root=outside)}\n")
    err = error_of(tree, check_tree)
    assert err.line == 3 and "is outside the allowed folders" in err.message and "add --include-path" in err.message
    assert SECRET[:20] not in str(err) and "root:" not in str(err)


def test_a_symbolic_link_out_of_the_folder_is_refused(outside):
    os.symlink(outside / "private" / "secret.yaml", outside / "trees" / "link.yaml")
    tree = write(outside, "trees/t.yaml", "type: Sequence\nchildren:\n  - include: link.yaml\n")
    err = error_of(tree, check_tree)
    assert "'link.yaml' is outside the allowed folders" in err.message


def test_include_path_opens_a_folder(outside):
    tree = write(outside, "trees/t.yaml", "type: Sequence\nchildren:\n  - include: ../private/leaf.yaml\n")
    check_tree(tree, include_path=[outside / "private"])
    assert main(["validate", str(tree), "--include-path", str(outside / "private")]) == 0


def test_an_allowed_file_that_is_no_tree_is_not_quoted(outside, capsys):
    tree = write(outside, "trees/t.yaml", "type: Sequence\nchildren:\n  - include: ../private/secret.yaml\n")
    assert main(["validate", str(tree), "--include-path", str(outside / "private")]) == 2
    err = capsys.readouterr().err
    assert "not a string: is it a tree file?" in err and SECRET[:20] not in err


def test_subfolders_and_the_shipped_trees_are_allowed(tmp_path):
    write(tmp_path, "sub/deeper/leaf.yaml", "type: Success\n")
    write(tmp_path, "sub/mid.yaml", "include: deeper/leaf.yaml\n")
    shipped = TREES_DIR / "subtrees" / "explore_then_home.yaml"
    tree = write(tmp_path, "t.yaml", f"type: Sequence\nchildren:\n  - include: sub/mid.yaml\n  - include: {shipped}\n")
    check_tree(tree)


def test_an_include_path_that_is_no_folder(tmp_path, capsys):
    assert main(["validate", str(tmp_path / "t.yaml"), "--include-path", str(tmp_path / "nope")]) == 2
    assert "is not a folder" in capsys.readouterr().err


# --------------------------------------------------------------------------- the command line


def one_line(capsys) -> str:
    captured = capsys.readouterr()
    err = captured.err.strip()
    assert "\n" not in err and "Traceback" not in err, err
    return err


def test_render_of_a_scenario_says_it_is_one(capsys, tmp_path):
    assert main(["render", str(DATA / "malformed" / "scenario_as_tree.yaml"), "--out", str(tmp_path / "t.txt")]) == 2
    assert "scenario_as_tree.yaml is a scenario, not a tree" in one_line(capsys)


def test_run_of_a_tree_says_it_is_one(capsys):
    assert main(["run", str(TREES_DIR / "frontier_explorer.yaml"), "--quiet"]) == 2
    assert re.search(r"frontier_explorer.yaml:\d+: frontier_explorer.yaml is a tree, not a scenario", one_line(capsys))


def test_validate_of_a_scenario_with_a_typo_in_a_top_level_key(tmp_path, capsys):
    path = write(tmp_path, "s.yaml", "name: s\nwrold: {generator: cave}\nrobots:\n  - {name: a, platform: legged, "
                                     f"tree: {TREES_DIR / 'frontier_explorer.yaml'}}}\n")
    assert main(["validate", str(path)]) == 2
    assert one_line(capsys).endswith("s.yaml:2: scenario: unknown key 'wrold' (did you mean 'world'?)")


def test_binary_files_exit_2_with_one_line(tmp_path, capsys):
    path = write(tmp_path, "t.yaml", os.urandom(4096) + b"\x00")
    assert main(["validate", str(path)]) == 2
    one_line(capsys)


def test_a_broken_mesh_prints_only_delves_line(capfd):
    """Open3D and its PLY reader (RPly) print from C++ straight to the process's stdout
    and stderr; none of it may come before delve's line."""
    assert main(["validate", str(DATA / "malformed_scenarios" / "broken_mesh.yaml")]) == 2
    out, err = capfd.readouterr()
    assert out == ""
    assert err.count("\n") == 1 and "cannot read mesh 'broken_mesh.ply'" in err, err


def test_a_file_that_is_no_scenario_is_refused_without_a_word_of_it(tmp_path, capsys):
    secret = "alice:$6$rounds=5000$SECRETSALT$HASH:19000:0:99999:7:::"
    path = write(tmp_path, "shadow", secret + "\n")
    assert main(["run", str(path), "--out", str(tmp_path / "out")]) == 2
    line = one_line(capsys)
    assert line.endswith("shadow:1: shadow is no scenario: none of its keys is a scenario's (name, description, "
                         "seed, duration_s, dt_s, coverage_period_s, ...)") and "SECRET" not in line
