"""Configuration checks that a JSON Schema cannot express, and seed derivation."""

from __future__ import annotations

import hashlib
import ntpath
import os
import posixpath
import re
from typing import NamedTuple


class ConfigError(ValueError):
    """A configuration value is wrong; the message names the key."""


def derive_seed(master: int, *names) -> int:
    """A 32-bit seed from the master seed and a path of names.

    Stable across runs, machines and Python versions (no ``hash()``), so a
    changed seed of one experiment reruns only that experiment's jobs.
    """
    text = "/".join([str(int(master))] + [str(n) for n in names])
    return int.from_bytes(hashlib.sha256(text.encode()).digest()[:4], "little")


def trial_records(trials) -> list[dict]:
    """The trial records of ``trials`` as a list, in config order.

    ``trials`` is a list of records (each with its ``id``), or a mapping trial id -> record: Snakemake merges
    mappings across ``--configfile`` files, so a config over ``config/cmu.yaml`` adds records by id without
    repeating the shipped ones (a later record of the same id replaces the earlier one, and ``ID: null`` drops
    it), while a list replaces every earlier config's trials. :func:`validate_config` turns the mapping into the
    list every other function reads.

    Raises
    ------
    ConfigError
        A mapping key that YAML read as a number (``35_16:`` is the integer 3516: quote it), or a record whose
        ``id`` differs from its key; the message names the key.
    """
    if not isinstance(trials, dict):
        return list(trials or [])
    out = []
    for key, rec in trials.items():
        if not isinstance(key, str):
            raise ConfigError(f"config key 'trials': the trial id {key!r} was read as a number (YAML reads 35_16 as "
                              f"3516); quote the id: \"{key}\":")
        if rec is None:  # dropped by a later config
            continue
        if "id" in rec and str(rec["id"]) != key:
            raise ConfigError(f"config key 'trials.{key}.id': {rec['id']!r} differs from its key {key!r} (in the "
                              "mapping form the key is the id; leave 'id' out)")
        out.append({"id": key, **{k: v for k, v in rec.items() if k != "id"}})
    return out


#: What an error about a trial id that has no record says about where to add one.
ADD_TRIAL = ("add its record to 'trials' in your config: as a mapping keyed by the quoted id (trials: {'ID': "
             "{subject: ..., kind: ..., amc: ..., asf: ...}}), which adds to the trials of the configs before it; "
             "a list of records replaces them all (docs/data.md, 'Adding a subject')")


#: Trial fields that name a file below ``data_dir`` / ``cmu_mirror``.
TRIAL_FILE_KEYS = ("amc", "asf", "bvh")


def resolve_inside(root: str, rel: str, key: str) -> str:
    """Join ``rel`` below ``root``, refusing any path text that leaves ``root``.

    ``rel`` must be a relative path that stays inside ``root`` after
    normalisation (no absolute path, drive letter, ``~`` or ``..`` escape).
    Symbolic links below ``root`` are followed wherever they point: a mirror
    may be a folder of links to the files of other mirrors (a merged mirror),
    and these files are only ever read (copied by the download job and checked
    against the record's SHA-256 when it gives one), never written. ``root`` may also be a URL
    (a mirror); the check is on the path text then too.

    Parameters
    ----------
    root : str
        ``data_dir`` or ``cmu_mirror``.
    rel : str
        The configured path, e.g. ``subjects/35/35_01.amc``.
    key : str
        The config key holding ``rel``, named in the error.

    Returns
    -------
    str
        ``root`` joined with the normalised ``rel``.

    Raises
    ------
    ConfigError
        The path is absolute or leaves ``root``; the message names ``key``.
    """
    if not isinstance(rel, str) or not rel.strip():
        raise ConfigError(f"config key '{key}': expected a file path relative to {root!r}, got {rel!r}")
    if posixpath.isabs(rel) or ntpath.isabs(rel) or ntpath.splitdrive(rel)[0] or rel.startswith("~"):
        raise ConfigError(f"config key '{key}': {rel!r} is an absolute path; give it relative to {root!r}")
    norm = posixpath.normpath(rel.replace("\\", "/"))
    if norm == ".." or norm.startswith("../") or norm == ".":
        raise ConfigError(f"config key '{key}': {rel!r} leaves {root!r}; paths must stay inside it")
    if "://" in root:
        return root.rstrip("/") + "/" + norm
    return os.path.join(root, *norm.split("/"))


#: Largest number of values a config may expand to (YAML aliases counted at
#: every use); the shipped configs have a few thousand.
MAX_CONFIG_VALUES = 200_000


def check_config_size(config, limit: int = MAX_CONFIG_VALUES) -> None:
    """Refuse a config whose YAML aliases expand past ``limit`` values (a
    "billion laughs" file) or refer to themselves, before anything walks it."""
    from .limits import count_nodes

    try:
        n = count_nodes(config, limit)
    except ValueError as exc:
        raise ConfigError(f"config: {exc}") from None
    if n > limit:
        raise ConfigError(f"config: more than {limit} values once YAML aliases (&name / *name) are expanded; "
                          "refusing it (a config this large is a mistake or an attack)")


def _yaml_children(node):
    import yaml

    if isinstance(node, yaml.MappingNode):
        return [x for pair in node.value for x in pair]
    if isinstance(node, yaml.SequenceNode):
        return node.value
    return None


def check_config_file(path, limit: int = MAX_CONFIG_VALUES) -> None:
    """Refuse a YAML config file whose aliases expand past ``limit`` values.

    The file is only composed (parsed into YAML nodes, an alias being a
    shared node), never constructed or merged, so neither list, dictionary
    nor merge-key (``<<: *name``) aliases can make this check slow. This is
    the check to run on a ``--configfile`` before Snakemake loads and merges
    it (``run.py`` does); :func:`check_config_size` is too late for
    dictionary aliases, which Snakemake's merge walks first.

    Raises
    ------
    ConfigError
        One line naming the file: too many values, a recursive alias, not
        readable, or not YAML.
    """
    import yaml

    from .limits import count_nodes

    try:
        with open(path, encoding="utf-8") as fh:
            root = yaml.compose(fh, Loader=yaml.SafeLoader)
    except OSError as exc:
        raise ConfigError(f"config file {os.fspath(path)}: cannot read it ({exc.strerror})") from None
    except (yaml.YAMLError, UnicodeDecodeError) as exc:
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise ConfigError(f"config file {os.fspath(path)}: not valid YAML ({first})") from None
    try:
        n = count_nodes(root, limit, children=_yaml_children)
    except ValueError as exc:
        raise ConfigError(f"config file {os.fspath(path)}: {exc}") from None
    if n > limit:
        raise ConfigError(f"config file {os.fspath(path)}: more than {limit} values once YAML aliases "
                          "(&name / *name) are expanded; refusing it (a config this large is a mistake or an attack)")


def check_results_dir(config: dict, project: str | None = None) -> None:
    """``results_dir`` is a relative path inside the project, or (with
    ``results_outside_project: true``) an absolute folder, or a relative path
    through a symbolic link, that is neither a filesystem root, the home
    folder, nor the project or a folder holding it. Symbolic links are
    resolved before the check, so a link inside the project that points
    outside it counts as outside."""
    rd = str(config.get("results_dir") or "results")
    project = os.path.realpath(project or os.getcwd())
    norm = posixpath.normpath(rd)
    if not posixpath.isabs(rd):
        if norm == "." or norm == ".." or norm.startswith("../"):
            raise ConfigError(f"config key 'results_dir': {rd!r} is not a folder inside the project {project!r}; "
                              "give a relative path such as results/myrun")
        # symbolic links resolved: a link inside the project may point anywhere
        real = os.path.realpath(os.path.join(project, norm))
        if real != project and os.path.commonpath([real, project]) == project:
            return
        if not config.get("results_outside_project"):
            raise ConfigError(f"config key 'results_dir': {rd!r} resolves to {real!r}, outside the project "
                              f"{project!r} (a symbolic link leaving it); give a folder inside the project, or set "
                              "results_outside_project: true to write to the folder the link names")
    elif not config.get("results_outside_project"):
        raise ConfigError(f"config key 'results_dir': {rd!r} is absolute; give a relative path inside the project, "
                          "or set results_outside_project: true to write to a folder you name explicitly")
    real = os.path.realpath(os.path.join(project, rd))
    home = os.path.realpath(os.path.expanduser("~"))
    if real == os.path.dirname(real) or real == home or os.path.commonpath([real, project]) == real:
        raise ConfigError(f"config key 'results_dir': {rd!r} is a filesystem root, the home folder, or holds the "
                          "project; name a dedicated folder")


def normalise_resequencing_trials(config: dict, defaults: dict | None = None) -> list[str]:
    """Leave out the re-sequencing studies a config does not give a trial for; return the notes logged.

    ``resequencing_trials`` may hold any subset of walk, run and dance: a key
    set to null is left out, and so is a key the user's config does not set
    whose value (merged in from the embedded default, ``defaults``) names a
    trial that is not among ``trials``. ``resequencing.datasets`` then keeps
    only the keys left. Changes ``config`` in place. A key the user set to an
    unknown trial id stays, and :func:`check_config` refuses it.
    """
    import logging

    log = logging.getLogger("animsynth.config")
    known = {t["id"] for t in config.get("trials", [])}
    rt = dict(config.get("resequencing_trials") or {})
    notes = []
    for key, tid in list(rt.items()):
        if tid is None:
            notes.append(f"config key 'resequencing_trials.{key}' is null: the {key} re-sequencing study is left out")
            del rt[key]
        elif tid not in known and defaults is not None and defaults.get(key) == tid:
            notes.append(f"config key 'resequencing_trials.{key}' is not set (the default {tid!r} is not one of "
                         f"your trials): the {key} re-sequencing study is left out")
            del rt[key]
    config["resequencing_trials"] = rt
    rs = config.get("resequencing")
    if isinstance(rs, dict) and "datasets" in rs:
        rs["datasets"] = [d for d in rs["datasets"] if d in rt]
    for n in notes:
        log.warning(n)
    return notes


def trial_mirror(config: dict, trial: dict) -> str | None:
    """Where one real trial's files are read from.

    Parameters
    ----------
    config : dict
        The whole config (``mocap_source``, ``cmu_mirror``, ``cmu_many_mirror``, ``data_dir``).
    trial : dict
        One record of ``trials``.

    Returns
    -------
    str or None
        ``data_dir`` for ``mocap_source: user``; for ``cmu``, ``cmu_many_mirror`` when the record sets
        ``mirror: many`` and that key is not null, else ``cmu_mirror``; None for synthetic trials.
    """
    src = config.get("mocap_source")
    if src == "synthetic":
        return None
    if src != "cmu":
        return config.get("data_dir")
    if trial.get("mirror") == "many" and config.get("cmu_many_mirror"):
        return config["cmu_many_mirror"]
    return config.get("cmu_mirror")


_CMU_TRIAL = re.compile(r"^(\d+)_\d+$")
_CMU_ASF = re.compile(r"(?:^|/)subjects/([^/]+)/([^/]+)\.asf$", re.IGNORECASE)


def asf_subject(path: str) -> str | None:
    """The subject whose skeleton a CMU ASF path names: ``SS`` of ``subjects/<SS>/<SS>.asf``.

    Returns None when the path is not of that form; a path whose folder and file name name different
    subjects (``subjects/16/127.asf``) gives ``"<folder>/<file>"``, which matches no trial.
    """
    m = _CMU_ASF.search(posixpath.normpath(str(path).replace("\\", "/")))
    if m is None:
        return None
    folder, stem = m.group(1), m.group(2)
    return folder if folder == stem else f"{folder}/{stem}"


def check_trial_skeleton(trial: dict, where: str, cmu: bool) -> None:
    """Refuse a real trial record that plays its motion on no skeleton or on another subject's.

    Parameters
    ----------
    trial : dict
        One record of ``trials`` (not synthetic).
    where : str
        How the error names the record, e.g. ``config key 'trials[3]' (id '127_09')``.
    cmu : bool
        ``mocap_source: cmu``: the ASF must be ``subjects/<SS>/<SS>.asf`` of the trial id's subject
        ``SS`` (``<SS>_<TT>``; the record's ``subject`` for an id of another form).

    Raises
    ------
    ConfigError
        An AMC file without ``asf`` (naming the AMC file), or, for CMU, an ASF file of another subject or
        not of the form ``subjects/<SS>/<SS>.asf`` (naming the trial id and the ASF file).
    """
    if "amc" in trial and "asf" not in trial:
        raise ConfigError(f"{where}: AMC file {trial['amc']!r} has no skeleton: give 'asf', the ASF file of its "
                          "subject (an AMC file holds joint angles only)")
    if not cmu or "asf" not in trial:
        return
    m = _CMU_TRIAL.match(str(trial["id"]))
    subject = m.group(1) if m else str(trial["subject"])
    got = asf_subject(trial["asf"])
    if got is None:
        raise ConfigError(f"{where}: ASF file {trial['asf']!r} is not subjects/<SS>/<SS>.asf, so whose skeleton it "
                          f"is cannot be told; give subjects/{subject}/{subject}.asf")
    if got != subject:
        raise ConfigError(f"{where}: trial {trial['id']!r} (subject {subject}) would be played on ASF file "
                          f"{trial['asf']!r}, the skeleton of subject {got}; a trial is read only with its own "
                          f"subject's skeleton: give subjects/{subject}/{subject}.asf")


#: the per-trial reading settings (:func:`trial_setting`), in the order the parse job's params list them
TRIAL_READ_KEYS = ("joint_roles", "bvh_length_to_m", "up_axis", "forward_axis")


def trial_setting(config: dict, trial: dict, key: str):
    """A per-trial setting: the trial record's ``key`` if it sets one, else the top-level config value.

    ``joint_roles`` merge (the trial's roles over the top-level ones); the
    others (``bvh_length_to_m``, ``up_axis``, ``forward_axis``) replace.
    """
    top = config.get(key)
    if key == "joint_roles":
        return {**(top or {}), **(trial.get(key) or {})}
    return trial[key] if trial.get(key) is not None else top


def check_config(config: dict) -> None:
    """Cross-key checks on a schema-validated config; raise :class:`ConfigError`.

    Every size that allocates (:func:`animsynth.limits.config_requests`, the
    synthetic trials' frames) is checked against ``memory_budget_gib`` here,
    before any job starts.
    """
    from .limits import DEFAULT_MEMORY_BUDGET_GIB, BudgetError, check_budget, config_requests, synthetic_trial_bytes

    check_results_dir(config)
    budget = float(config.get("memory_budget_gib", DEFAULT_MEMORY_BUDGET_GIB))
    for what, nbytes in config_requests(config):
        try:
            check_budget(what, nbytes, budget)
        except BudgetError as exc:
            raise ConfigError(str(exc)) from None
    ids = [t["id"] for t in config["trials"]]
    dup = sorted({i for i in ids if ids.count(i) > 1})
    if dup:
        raise ConfigError(f"config key 'trials': duplicate id(s) {dup}")
    known = set(ids)
    src = config["mocap_source"]
    if src == "user" and not config.get("data_dir"):
        raise ConfigError("config key 'data_dir': mocap_source 'user' needs the folder holding your files")
    for k, t in enumerate(config["trials"]):
        where = f"config key 'trials[{k}]' (id {t['id']!r})"
        if src == "synthetic":
            if "frames" not in t:
                raise ConfigError(f"{where}: synthetic trials need 'frames'")
            try:
                check_budget(f"config keys 'trials[{k}].frames' ({t['frames']}) x 'fps' ({config.get('fps', 120)})",
                             synthetic_trial_bytes(t["frames"], float(config.get("fps", 120))), budget)
            except BudgetError as exc:
                raise ConfigError(str(exc)) from None
            if t["kind"] not in ("walk_straight", "walk_turn", "run_straight", "run_turn", "dance"):
                raise ConfigError(f"{where}: the synthetic generator cannot make kind {t['kind']!r}")
        else:
            check_trial_skeleton(t, where, cmu=src == "cmu")
            has_amc = "amc" in t and "asf" in t
            if not has_amc and "bvh" not in t:
                raise ConfigError(f"{where}: mocap_source {src!r} needs 'amc' and 'asf', or 'bvh'")
            if t.get("mirror", "main") != "main" and src != "cmu":
                raise ConfigError(f"config key 'trials[{k}].mirror': {t['mirror']!r} needs mocap_source 'cmu' "
                                  f"(mocap_source {src!r} reads every trial from data_dir)")
            if src == "cmu" and "sha256" not in t:
                raise ConfigError(f"{where}: CMU trials need 'sha256' (LF-normalised) so downloads are verified")
            for ax in ("up_axis", "forward_axis"):
                if t.get(ax) is not None and t.get(ax) != "auto":
                    from .kinematics import parse_axis

                    try:
                        parse_axis(t[ax])
                    except ValueError as exc:
                        raise ConfigError(f"config key 'trials[{k}].{ax}': {exc}") from None
            up, fwd = trial_setting(config, t, "up_axis"), trial_setting(config, t, "forward_axis")
            if up not in (None, "auto") and fwd not in (None, "auto") and up[-1] == fwd[-1]:
                raise ConfigError(f"{where}: up_axis {up!r} and forward_axis {fwd!r} must be perpendicular")
            root = trial_mirror(config, t)
            for field in TRIAL_FILE_KEYS:
                if field in t:
                    resolve_inside(root or ".", t[field], f"trials[{k}].{field}")
    subsets = {k: v for k, v in config["subsets"].items() if v}
    if not subsets:
        raise ConfigError("config key 'subsets': at least one subset is needed")
    for name, members in subsets.items():
        bad = [m for m in members if m not in known]
        if bad:
            raise ConfigError(f"config key 'subsets.{name}': trial(s) {', '.join(map(repr, bad))} have no record in "
                              f"'trials' ({len(known)} records); {ADD_TRIAL}")
    for name, tid in config["resequencing_trials"].items():
        if tid not in known:
            raise ConfigError(f"config key 'resequencing_trials.{name}': trial {tid!r} has no record in 'trials'; "
                              f"{ADD_TRIAL}")


def unused_trials(config: dict) -> list[str]:
    """The trials of ``trials`` that no family uses (in no subset of ``subsets`` and no clip of
    ``resequencing_trials``), one line each naming those keys (the workflow prints them at parse time on a
    user's data: such a trial is never read)."""
    used = {t for ids in config["subsets"].values() if ids for t in ids} | set(config["resequencing_trials"].values())
    return [f"trial {t['id']!r} is in no subset (subsets) and no re-sequencing clip (resequencing_trials): no "
            "family uses it" for t in config["trials"] if t["id"] not in used]


def _where(path) -> str:
    out = ""
    for p in path:
        out += f"[{p}]" if isinstance(p, int) else (f".{p}" if out else str(p))
    return out


def explain_schema_error(config: dict, schema: dict) -> str | None:
    """A few lines about the most relevant schema violation, or None if valid.

    For an unknown key: the key, where it is, and the closest valid key (the
    default message of a JSON Schema validator prints the whole schema and
    config, thousands of lines).
    """
    import difflib

    import jsonschema

    cls = jsonschema.validators.validator_for(schema)
    error = jsonschema.exceptions.best_match(cls(schema).iter_errors(config))
    if error is None:
        return None
    where = _where(error.absolute_path)
    if error.validator == "additionalProperties" and isinstance(error.instance, dict):
        props = sorted(error.schema.get("properties", {}))
        patterns = list(error.schema.get("patternProperties", {}))
        extra = sorted(k for k in error.instance if k not in props and not any(re.search(p, k) for p in patterns))
        lines = []
        for key in extra:
            full = f"{where}.{key}" if where else key
            lines.append(f"config key '{full}' is not allowed ({'in ' + repr(where) if where else 'at the top level'})")
            close = difflib.get_close_matches(key, props, n=1, cutoff=0.5)
            lines.append(f"  closest valid key: '{close[0]}'" if close else
                         "  valid keys there: " + ", ".join(props))
        lines.append("  (keys and their meaning: config/README.md and config/schema.yaml)")
        return "\n".join(lines)
    message = error.message if len(error.message) <= 300 else error.message[:300] + " ..."
    return (f"config key '{where or '<top level>'}': {message}\n"
            "  (keys and their meaning: config/README.md and config/schema.yaml)")


def check_finite(config, path=()) -> None:
    """Refuse NaN and infinity anywhere in ``config``, naming the key.

    A JSON Schema ``minimum`` / ``maximum`` cannot refuse NaN (every
    comparison with NaN is false), so ``memory_budget_gib: .nan`` would switch
    every budget check off and ``fps: .nan`` fail deep inside a job.
    """
    import math

    if isinstance(config, float):
        if not math.isfinite(config):
            raise ConfigError(f"config key '{_where(path) or '<top level>'}': {config!r} is not a finite number")
    elif isinstance(config, dict):
        for k, v in config.items():
            check_finite(v, path + (k,))
    elif isinstance(config, (list, tuple)):
        for i, v in enumerate(config):
            check_finite(v, path + (i,))


def check_keys(config, path=()) -> None:
    """Refuse a mapping key that is not text (YAML reads ``1:`` and ``35_16:`` as numbers, ``yes:`` as a boolean),
    naming where it is: JSON Schema's name patterns cannot be matched against it, so the validator would stop
    with a traceback. The ids of a ``trials`` mapping are left to :func:`trial_records`, whose message names the
    trial."""
    if isinstance(config, dict):
        for k, v in config.items():
            if not isinstance(k, str) and path != ("trials",):
                kind = "boolean" if isinstance(k, bool) else "number" if isinstance(k, (int, float)) else "value"
                raise ConfigError(f"config key '{_where(path) or '<top level>'}': the key {k!r} was read as a {kind} "
                                  f"(YAML reads 35_16 as 3516, yes as true); quote it: \"{k}\":")
            check_keys(v, path + (k,))
    elif isinstance(config, (list, tuple)):
        for i, v in enumerate(config):
            check_keys(v, path + (i,))


def _schema_keys(config: dict, schema: dict):
    """Every ``(mapping, key, value, key's schema, its types)`` of ``config`` that the schema's properties describe,
    depth first (a mapping value whose schema has properties: its keys after it)."""
    props = schema.get("properties") or {}
    for key, value in list(config.items()):
        sub = props.get(key)
        if not isinstance(sub, dict):
            continue
        types = sub.get("type")
        yield config, key, value, sub, [types] if isinstance(types, str) else (types or [])
        if isinstance(value, dict) and sub.get("properties"):
            yield from _schema_keys(value, sub)


def coerce_booleans(config: dict, schema: dict) -> None:
    """Read the text ``true`` / ``false`` (any case) of a boolean schema key as a boolean, in place.

    Snakemake's ``--config key=value`` keeps ``true`` as text (only ``True`` /
    ``False`` become booleans), so ``--config results_outside_project=true``
    would be refused as a string.
    """
    for mapping, key, value, _, types in _schema_keys(config, schema):
        if "boolean" in types and isinstance(value, str) and value.strip().lower() in ("true", "false"):
            mapping[key] = value.strip().lower() == "true"


def null_means_off(config: dict, schema: dict) -> None:
    """A ``null`` given to a schema block that may be null and has an ``enabled`` switch (``compare.long_track``:
    "null or enabled: false: off") becomes ``{"enabled": false}``, in place, before validation: the validator
    fills in the block's defaults and cannot fill them into ``null``."""
    for mapping, key, value, sub, types in _schema_keys(config, schema):
        if value is None and {"object", "null"} <= set(types) and "enabled" in (sub.get("properties") or {}):
            mapping[key] = {"enabled": False}


class _Schema(NamedTuple):
    """One version of a schema file: its modification time and size, the parsed schema, its validator."""

    mtime_ns: int
    size: int
    schema: dict
    validator: object


#: :func:`_schema_entry`'s parsed schemas: ``{absolute path: _Schema}``.
_SCHEMAS: dict = {}


def _schema_entry(schema_path: str) -> _Schema:
    """The YAML JSON Schema at ``schema_path`` and its default-filling validator, built once per process and
    version of the file (its modification time and size). The schema is parsed with libyaml's loader where PyYAML
    has it (the same document as the pure-Python loader's, about nine times faster); the test suite validates
    over a hundred configs, and every Snakemake call one."""
    import yaml

    st = os.stat(schema_path)
    key = os.path.abspath(schema_path)
    hit = _SCHEMAS.get(key)
    if hit is None or hit[:2] != (st.st_mtime_ns, st.st_size):
        with open(schema_path, encoding="utf-8") as fh:
            schema = yaml.load(fh, Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader))
        hit = _SCHEMAS[key] = _Schema(st.st_mtime_ns, st.st_size, schema, _default_filling_validator(schema))
    return hit


def _read_schema(schema_path: str) -> dict:
    """The YAML JSON Schema at ``schema_path`` (parsed once per process and file version), handed out as a copy."""
    import copy

    return copy.deepcopy(_schema_entry(schema_path).schema)


def _default_filling_validator(schema: dict):
    """A validator of ``schema`` (of the dialect its ``$schema`` names, 2020-12 by default, as
    :func:`explain_schema_error` reads it) that fills in each missing property's ``default`` as it validates: the
    validator that :func:`snakemake.utils.validate` builds (jsonschema's documented ``extend_with_default``), here
    built once per schema instead of once per call. Unlike snakemake's, it deep-copies each default, so that no
    two configs (nor two items of one array) share a default list or mapping with the cached schema, and it fills
    nothing into a value that is not a mapping (the type check then names it; snakemake's stops on
    ``setdefault``). The schema's ``$ref`` are local (``#/$defs/...``), so it needs no registry."""
    import copy

    from jsonschema import Draft202012Validator, validators

    base = validators.validator_for(schema, default=Draft202012Validator)
    check_properties = base.VALIDATORS["properties"]

    def fill_defaults(validator, properties, instance, subschema):
        if isinstance(instance, dict):
            for name, sub in properties.items():
                if "default" in sub and name not in instance:
                    instance[name] = copy.deepcopy(sub["default"])
        yield from check_properties(validator, properties, instance, subschema)

    return validators.extend(base, {"properties": fill_defaults})(schema)


def validate_config(config: dict, schema_path: str) -> None:
    """Validate ``config`` against the YAML JSON Schema and fill in defaults.

    A config whose YAML aliases expand past :data:`MAX_CONFIG_VALUES` values
    is refused first (:func:`check_config_size`), so validation never walks a
    "billion laughs" file; then any NaN or infinite number
    (:func:`check_finite`: the schema's minimum and maximum let NaN through), and any key that is not text
    (:func:`check_keys`).
    ``true`` / ``false`` given as text (``--config key=true``) to a boolean
    key are read as booleans (:func:`coerce_booleans`); ``null`` given to a block with an ``enabled`` switch is
    ``enabled: false`` (:func:`null_means_off`).

    Validates as :func:`snakemake.utils.validate` does, filling in defaults (:func:`_default_filling_validator`,
    the same validator built once per schema), so that a violation raises a :class:`ConfigError` of a few lines
    (see :func:`explain_schema_error`) instead of the validator's dump. Afterwards
    ``trials`` is a list (:func:`trial_records`: the mapping form becomes one).
    """
    import copy

    check_config_size(config)
    check_finite(config)
    check_keys(config)
    entry = _schema_entry(schema_path)
    coerce_booleans(config, entry.schema)  # these two and explain_schema_error only read the cached schema
    null_means_off(config, entry.schema)
    try:
        entry.validator.validate(config)
    except Exception as exc:  # jsonschema's message embeds the failing part of the schema and config
        short = explain_schema_error(config, copy.deepcopy(entry.schema))
        if short is None:
            short = "\n".join(str(exc).splitlines()[:5])
        raise ConfigError(short) from None
    if "trials" in config:
        config["trials"] = trial_records(config["trials"])
