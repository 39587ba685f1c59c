"""delve.executive.errors: one-line messages with file, line and node."""
from __future__ import annotations

import os
import pickle

from delve.executive.errors import DelveError, did_you_mean, display_path


def test_str_has_file_line_message_and_node():
    err = DelveError("unknown behaviour type 'Explor' (did you mean 'Explore'?)", "trees/x.yaml", 12)
    assert str(err) == "trees/x.yaml:12: unknown behaviour type 'Explor' (did you mean 'Explore'?)"
    err = DelveError("parameter 'timeout_s' must be >= 0", "trees/x.yaml", 30, node="Go home")
    assert str(err) == "trees/x.yaml:30: parameter 'timeout_s' must be >= 0 [node 'Go home']"


def test_str_without_line_or_file():
    assert str(DelveError("file not found", "a.yaml")) == "a.yaml: file not found"
    assert str(DelveError("bad format")) == "bad format"


def test_absolute_paths_below_cwd_are_shown_relative():
    inside = os.path.join(os.getcwd(), "trees", "x.yaml")
    assert display_path(inside) == os.path.join("trees", "x.yaml")
    assert str(DelveError("m", inside, 3)).startswith(os.path.join("trees", "x.yaml") + ":3: ")
    outside = os.path.join(os.path.dirname(os.getcwd().rstrip(os.sep)) or os.sep, "elsewhere.yaml")
    assert display_path(outside) == outside


def test_did_you_mean():
    assert did_you_mean("Explor", ["Explore", "Home"]) == " (did you mean 'Explore'?)"
    assert did_you_mean("sequence", ["Sequence"]) == " (did you mean 'Sequence'?)"
    assert did_you_mean("zzz", ["Explore"]) == ""


def test_pickles_with_location():
    err = pickle.loads(pickle.dumps(DelveError("m", "a.yaml", 2, "n")))
    assert (err.message, err.file, err.line, err.node) == ("m", "a.yaml", 2, "n")
