"""Small COPS networks shared by the planner tests."""
from delve.planners.cops import ConnectivityProblem, MCNetwork, network_from_dict


def fork(robots: list[dict], frontiers: tuple[str, ...] = ("a3", "b3"),
         comm: str | list = "adjacent") -> MCNetwork:
    """Base s0 - s1, then two branches a1..a3 and b1..b3."""
    locs = ["s0", "s1", "a1", "a2", "a3", "b1", "b2", "b3"]
    mob = [["s0", "s1"], ["s1", "a1"], ["a1", "a2"], ["a2", "a3"], ["s1", "b1"], ["b1", "b2"], ["b2", "b3"]]
    return network_from_dict({
        "base": "s0", "locations": locs, "mobility": mob,
        "communication": mob if comm == "adjacent" else comm,
        "robots": [{"name": "base", "location": "s0", "static": True}] + robots,
        "base_station": "base", "frontiers": list(frontiers)})


def team(n: int, **kw) -> list[dict]:
    """Robots r1..rn at the base location s0."""
    return [dict({"name": f"r{i}", "location": "s0"}, **kw) for i in range(1, n + 1)]


def line(n: int, robots: list[dict], comm: list | None = None, **extra) -> MCNetwork:
    """Locations s0..s(n-1) in a line, the static base station at s0."""
    names = [f"s{i}" for i in range(n)]
    d = {"base": "s0", "locations": names,
         "mobility": [[a, b] for a, b in zip(names, names[1:])],
         "communication": comm if comm is not None else [[a, b] for a, b in zip(names, names[1:])],
         "robots": [{"name": "base", "location": "s0", "static": True}] + robots,
         "base_station": "base"}
    d.update(extra)
    return network_from_dict(d)


def problem(net: MCNetwork, T: int, **kw) -> ConnectivityProblem:
    """The connectivity problem of ``net`` at horizon T, the base station as master."""
    kw.setdefault("positions", net.positions())
    kw.setdefault("masters", {"base"})
    kw.setdefault("static", net.static_robots())
    kw.setdefault("explorers", net.explorers())
    return ConnectivityProblem(network=net, horizon=T, **kw)


def cut_off() -> MCNetwork:
    """A line s0..s5 with radio only between s0 and s1 (r1 at s5), and apart from it
    x1 - x2 (the frontier) with a robot r2 at x1 that cannot explore."""
    return network_from_dict({
        "base": "s0", "locations": ["s0", "s1", "s2", "s3", "s4", "s5", "x1", "x2"],
        "mobility": [["s0", "s1"], ["s1", "s2"], ["s2", "s3"], ["s3", "s4"], ["s4", "s5"], ["x1", "x2"]],
        "communication": [["s0", "s1"]],
        "robots": [{"name": "base", "location": "s0", "static": True}, {"name": "r1", "location": "s5"},
                   {"name": "r2", "location": "x1", "explorer": False}],
        "base_station": "base", "frontiers": ["x2"]})
