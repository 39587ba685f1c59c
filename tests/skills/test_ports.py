"""Every skill declares the blackboard keys it reads and writes (INPUT_PORTS and
OUTPUT_PORTS, py_trees' PortInformation) and registers exactly those, with the right
access: inputs READ, outputs WRITE."""
from __future__ import annotations

import pytest
from delve.skills import all_skills
from delve.skills.base import AgentContext, ParamNamedPort, Skill, port_key_param, resolve_key
from delve.skills.cops import ActionTimer, CopsState, IsExploring, TransitionAction
from delve.skills.motion import GoTo
from py_trees.common import Status
from py_trees.ports import PortInformation

from .fakes import Clock

SKILLS = all_skills()
#: A value for each required parameter of a skill (none has a default).
REQUIRED_VALUES = {"duration_s": 1.0}


def make_ctx(name: str = "r1") -> AgentContext:
    return AgentContext(name=name, namespace=f"/{name}", clock=Clock(), log=lambda *a, **k: None)


def build(cls: type[Skill], remap: dict[str, str] | None = None, **params) -> Skill:
    given = {p: REQUIRED_VALUES[p] for p, spec in cls.PARAMS.items() if spec.required}
    return cls(name=cls.__name__, ctx=make_ctx(), remap=remap, **{**given, **params})


def expected_keys(node: Skill, ports: dict[str, PortInformation]) -> set[str]:
    """The full keys of ``ports`` as the declarations and the node's parameters say."""
    out = set()
    for port, info in ports.items():
        param = port_key_param(info)
        key = port if param is None else node.p[param]
        if key is not None:
            out.add(resolve_key(key, node.ctx.namespace, node.remap))
    return out


def key_params(cls: type[Skill]) -> dict[str, str]:
    """A key name for every parameter that names a port's key."""
    return {port_key_param(info): f"my_{port}" for info_map in (cls.INPUT_PORTS, cls.OUTPUT_PORTS)
            for port, info in info_map.items() if port_key_param(info) is not None}


def test_there_are_skills_with_ports():
    assert len(SKILLS) >= 30
    assert sum(bool(c.INPUT_PORTS or c.OUTPUT_PORTS) for c in SKILLS.values()) >= 25


@pytest.mark.parametrize("name", sorted(SKILLS))
def test_declarations_are_py_trees_ports(name):
    cls = SKILLS[name]
    for ports in (cls.INPUT_PORTS, cls.OUTPUT_PORTS):
        for port, info in ports.items():
            assert isinstance(info, PortInformation), (name, port)
            assert info.description, f"{name}: port {port!r} says nothing about what it holds"
            param = port_key_param(info)
            if param is not None:  # the parameter that names the key is a key parameter of the skill
                assert cls.PARAMS[param].key, (name, port, param)
    for port in cls.INPUT_PORTS.keys() & cls.OUTPUT_PORTS.keys():  # read and written: one key
        assert port_key_param(cls.INPUT_PORTS[port]) == port_key_param(cls.OUTPUT_PORTS[port]), (name, port)


@pytest.mark.parametrize("rename", [False, True], ids=["defaults", "renamed"])
@pytest.mark.parametrize("name", sorted(SKILLS))
def test_registered_keys_are_the_declared_ones_with_their_access(name, rename):
    cls = SKILLS[name]
    params = key_params(cls) if rename else {}
    remap = {"goal": "/shared/target", "mode": "robot_mode"} if rename else None
    node = build(cls, remap, **params)
    inputs_only = {p: i for p, i in cls.INPUT_PORTS.items() if p not in cls.OUTPUT_PORTS}
    client = node.bb
    assert client.read == expected_keys(node, inputs_only)
    assert client.write == expected_keys(node, cls.OUTPUT_PORTS)
    assert not client.exclusive
    # No declared input is opened for writing (unless the skill also declares it an output).
    assert not client.write & expected_keys(node, inputs_only)
    assert set(node.keys.values()) == client.read | client.write


def test_key_parameters_and_remaps_rename_the_keys():
    node = build(GoTo, {"target": "/shared/target"}, goal_key="target")
    assert node.keys == {"goal": "/shared/target", "goto_failure": "/r1/goto_failure",
                         "goto_path_length_m": "/r1/goto_path_length_m"}


def test_a_key_named_by_a_null_parameter_is_not_registered():
    backtrack = SKILLS["Backtrack"]
    node = build(backtrack)
    assert "until" not in node.keys and node.read("until") is None
    node = build(backtrack, until_key="ping_ok")
    assert node.keys["until"] == "/r1/ping_ok" and node.bb.read == {"/r1/ping_ok"}


def test_undeclared_access_fails_loudly():
    node = build(GoTo)
    with pytest.raises(KeyError, match="declares no output port 'goal'"):
        node.write("goal", [0.0, 0.0, 0.0])
    with pytest.raises(KeyError, match="declares no input port 'goto_failure'"):
        node.read("goto_failure")
    with pytest.raises(AttributeError, match="does not have write access"):
        node.bb.set(node.keys["goal"], [0.0, 0.0, 0.0])  # py_trees' client: an input is READ
    with pytest.raises(AttributeError, match="does not have read/write access"):
        node.bb.get("/r1/mode")


def test_read_gives_the_default_until_the_key_is_written():
    node = build(GoTo)
    assert node.read("goal") is None and node.read("goal", [1.0, 2.0, 3.0]) == [1.0, 2.0, 3.0]
    writer = build(SKILLS["ProcessOperatorCommands"])
    writer.write("goal", [4.0, 5.0, 6.0])
    assert node.read("goal") == [4.0, 5.0, 6.0]


def test_declared_input_defaults_are_what_read_gives():
    class WithDefault(Skill):
        ABSTRACT = True
        INPUT_PORTS = {"speed_mps": PortInformation(float, required=False, description="speed", default_value=1.5)}

        def update(self) -> Status:
            return Status.SUCCESS

    node = WithDefault(name="d", ctx=make_ctx())
    assert node.read("speed_mps") == 1.5


def test_a_param_named_port_needs_its_parameter():
    with pytest.raises(ValueError, match="key_param"):
        ParamNamedPort(str, description="nothing names it")


def test_cops_behaviours_that_only_read_the_state_do_not_store_one():
    for cls in (ActionTimer, IsExploring):
        node = build(cls)
        assert node.bb.read == {"/r1/cops"} and not node.bb.write
        assert isinstance(node.state, CopsState)
        assert node.stored_state() is None
    writer = build(TransitionAction)
    assert writer.bb.write == {"/r1/cops"} and writer.state is writer.stored_state()
    reader = build(IsExploring)
    writer.state.part = "explore"
    reader.tick_once()
    assert reader.status == Status.SUCCESS


def test_a_key_read_and_written_is_registered_once_for_write():
    node = build(SKILLS["DeployBreadcrumb"])
    assert node.bb.write == {"/r1/breadcrumb_request", "/r1/link_loss_points"} and not node.bb.read
    assert "breadcrumb_request" in node.INPUT_PORTS and "breadcrumb_request" in node.OUTPUT_PORTS
