"""Memory budget: refuse a request before allocating arrays that would not fit.

A request (a CLI ``--steps`` / ``--length``, a config's trial frames) is turned
into an estimate of the bytes its largest arrays need; above the budget it is
refused with one line naming the argument (or config key) and the estimate,
before any work starts. The budget is :data:`DEFAULT_MEMORY_BUDGET_GIB` unless
configured (CLI ``--memory-budget-gib``, config key ``memory_budget_gib``).
"""

from __future__ import annotations

GIB = float(2**30)

#: Default budget (GiB) for the arrays of one request.
DEFAULT_MEMORY_BUDGET_GIB = 4.0


class BudgetError(ValueError):
    """A request's arrays would exceed the memory budget (the message names the argument)."""


def check_budget(what: str, nbytes: float, budget_gib: float = DEFAULT_MEMORY_BUDGET_GIB) -> None:
    """Raise :class:`BudgetError` when ``nbytes`` exceeds ``budget_gib``.

    Parameters
    ----------
    what : str
        The argument or config key and its value, e.g. ``"--steps 1000000000"``.
    nbytes : float
        Estimated bytes of the arrays the request allocates.
    budget_gib : float
        The budget in GiB (2**30 bytes).
    """
    if nbytes > budget_gib * GIB:
        raise BudgetError(f"{what} needs about {nbytes / GIB:.3g} GiB of arrays, over the memory budget of "
                          f"{budget_gib:g} GiB (raise it with --memory-budget-gib / memory_budget_gib)")


def synthetic_trial_bytes(frames: int, fps: float, n_dof: int = 62) -> float:
    """Bytes the synthetic mocap generator allocates for one trial (values,
    per-joint rotations, and smoothing noise padded by a few seconds)."""
    return 8.0 * (4 * frames * n_dof + 4 * (frames + 6 * fps) * 3)


def _python_children(o):
    if isinstance(o, dict):
        return list(o.keys()) + list(o.values())
    if isinstance(o, (list, tuple)):
        return o
    return None


def count_nodes(obj, limit: int, children=_python_children) -> int:
    """Number of values in ``obj`` with every shared reference (a YAML alias)
    counted each time it is reached, stopping past ``limit``.

    Parameters
    ----------
    obj : object
        Loaded YAML (dicts, lists, scalars), or any graph ``children`` knows.
    limit : int
    children : callable, optional
        ``children(o)``: the values inside ``o``, or None for a leaf (default:
        dict keys and values, list and tuple items).

    Returns the count (at most ``limit + 1``). Raises ``ValueError`` for a
    structure that contains itself (a recursive alias).
    """
    count = 0
    stack = [(obj, ())]
    while stack:
        o, ancestors = stack.pop()
        count += 1
        if count > limit:
            return count
        items = children(o)
        if items is not None:
            if id(o) in ancestors:
                raise ValueError("the config contains itself (a recursive YAML alias)")
            inner = ancestors + (id(o),)
            stack.extend((x, inner) for x in items)
    return count


#: Body vertices of the synthetic skirt character at resolution 1 (measured: a
#: few thousand); the count grows with the square of ``resolution``.
CHARACTER_BODY_VERTICES = 4000

#: Joint angles a decoded simplicial path carries per frame (CMU skeleton, root excluded).
SIMPLICIAL_POSE_DOF = 56


def config_requests(config: dict) -> list[tuple[str, float]]:
    """The sizes of a config that allocate, each as (config keys and values, bytes).

    Every estimate counts the largest float64 arrays of one job of the run
    (what a job holds at once, not the total of the run), so a size the
    memory budget refuses here would end in a MemoryError later. The config
    is a schema-validated one (defaults filled in); missing blocks count as
    their defaults.

    Returns
    -------
    list of (str, float)
        ``what`` names the keys and their values, e.g.
        ``"config key 'simplicial.steps' (1000000)"``; the bytes are the
        estimate for that request.
    """
    out = []
    s = config.get("simplicial") or {}
    steps = s.get("steps", "held_out")
    if isinstance(steps, int) and not isinstance(steps, bool):
        starts = int((s.get("ensemble") or {}).get("n_starts", 16)) + 1
        variants = len(s.get("methods") or [0, 0])
        dims = [int(s.get("latent_dim", 2))] + [int(d) for d in (s.get("beyond") or {}).get("latent_dims") or [4]]
        d = max(dims)
        # one fold job: batched path points and velocities of every start and method, plus decoded poses
        out.append((f"config key 'simplicial.steps' ({steps}) x {starts} starts x {variants} methods",
                    8.0 * (steps + 1) * (starts * variants * 2 * d + starts * SIMPLICIAL_POSE_DOF)))
    beyond = s.get("beyond") or {}
    if "max_all_pairs" in beyond:
        n = int(beyond["max_all_pairs"])
        out.append((f"config key 'simplicial.beyond.max_all_pairs' ({n}): up to {n} x {n} shortest-path matrices",
                    8.0 * 2 * n * n))
    m = config.get("meshdetail") or {}
    ch = m.get("character") or {}
    if not config.get("mesh_dir"):
        rings, around = int(ch.get("skirt_rings", 16)), int(ch.get("skirt_around", 56))
        frames = int(ch.get("frames", 160))
        res = float(ch.get("resolution", 1.0))
        verts = CHARACTER_BODY_VERTICES * res * res + rings * around
        clips = 1 + len(ch.get("edits") or [])
        # vertex positions of the main clip and every edit, plus four predictions of the main clip
        out.append((f"config keys 'meshdetail.character.skirt_rings' ({rings}) x 'skirt_around' ({around}) x "
                    f"'frames' ({frames}) x 'resolution' ({res:g})",
                    8.0 * 3 * frames * verts * (clips + 4)))
    return out
