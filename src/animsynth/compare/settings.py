"""Cross-key checks of the ``compare`` config block (beyond the JSON Schema) and what the workflow reads of it.

Defaults live only in ``config/schema.yaml`` (the validator fills them in); every key is documented in
``config/README.md`` and ``docs/compare.md``.
"""

from __future__ import annotations

import logging

from ..config import ConfigError

log = logging.getLogger("animsynth.compare")

__all__ = ["check", "groups", "held_out_trials", "trial_subjects", "first_frames", "subject_groups", "subject_showcase",
           "subject_sets", "showcase", "run_generators", "clips_cfg", "native_rates",
           "job_cfg", "unavailable", "user_generators", "generator_order", "user_job_cfg", "left_out", "trial_rate",
           "check_subject_sets", "check_trial_rates", "common_rates", "CLIP_KEYS", "RUN_KEYS", "GENERATOR_BLOCKS"]


def subject_sets(config: dict) -> dict:
    """``{name: [trial ids]}`` of ``compare.subjects`` (the comparison's own per-subject sets), in config order.

    A later config drops one set with ``name: null`` and every set with ``subjects: null`` (configs merge)."""
    return {k: list(v) for k, v in (config["compare"].get("subjects") or {}).items() if v is not None}


def groups(config: dict, missing=()) -> tuple[dict, dict]:
    """The databases of the comparison: ``({group: [trial ids]}, {group: trial id})`` in config order.

    Parameters
    ----------
    config : dict
        The whole (validated) config.
    missing : collection of str
        Trial ids whose files cannot be read in this run (a mirror that is not there, with
        ``on_missing_data: skip``): every group holding one is left out.

    Returns
    -------
    (dict, dict)
        The leave-one-out groups: the subsets of ``compare.subsets`` that the run has (null: every subset),
        then the sets of ``compare.subjects`` with two or more trials; the temporal splits: the clips of
        ``compare.resequencing`` (null: every re-sequencing clip of the run), then the sets of
        ``compare.subjects`` with one trial.
    """
    cmp = config["compare"]
    subsets = {k: list(v) for k, v in config["subsets"].items() if v}
    reseq = dict(config["resequencing_trials"])
    use_s = list(subsets) if cmp["subsets"] is None else cmp["subsets"]
    use_r = list(reseq) if cmp["resequencing"] is None else cmp["resequencing"]
    loo = {s: subsets[s] for s in use_s if s in subsets}
    split = {d: reseq[d] for d in use_r if d in reseq}
    for name, ids in subject_sets(config).items():
        if len(ids) >= 2:
            loo[name] = ids
        elif ids:
            split[name] = ids[0]
    gone = set(missing)
    return ({g: ids for g, ids in loo.items() if not gone & set(ids)},
            {g: t for g, t in split.items() if t not in gone})


def held_out_trials(config: dict, missing=()) -> list[str]:
    """Every held-out part's trial of the protocol: ``<group>/<trial>`` of the leave-one-out groups, then of the
    temporal splits (:func:`groups`; ``missing``: trial ids left out of this run). A clip's id adds the window's
    first frame, ``<group>/<trial>@<frame>``, known once the trials are read (the clips job)."""
    subsets, reseq = groups(config, missing)
    return [f"{s}/{t}" for s, ids in subsets.items() for t in ids] + [f"{d}/{t}" for d, t in reseq.items()]


def trial_subjects(config: dict) -> dict:
    """``{trial id: subject}`` from the trial records (their ``subject``)."""
    return {str(t["id"]): str(t["subject"]) for t in config["trials"]}


def subject_groups(config: dict, missing=()) -> dict:
    """``{subject: (leave-one-out groups, temporal splits)}``: :func:`groups` split by subject, the comparison's unit
    of work (one clips job and one job per generator per subject). A group's subject is its trials' ``subject``
    (:func:`animsynth.compare.protocol.group_subject`: joined by ``+`` when they differ); subjects in the order of
    their first group."""
    from .protocol import group_subject

    subsets, reseq = groups(config, missing)
    subj = trial_subjects(config)
    out: dict = {}
    for g, ids in subsets.items():
        out.setdefault(group_subject(ids, subj, g), ({}, {}))[0][g] = ids
    for g, t in reseq.items():
        out.setdefault(group_subject([t], subj, g), ({}, {}))[1][g] = t
    return out


def showcase(config: dict, missing=()) -> tuple[str | None, int, str]:
    """The strips figure's and the BVH files' clip, seed index and subject: ``compare.showcase.clip`` (a held-out
    trial ``<group>/<trial>``: its first clip; or a clip ``<group>/<trial>@<frame>``) or, when null, the first
    clip of the first subject (``None``)."""
    sc = config["compare"]["showcase"]
    spec = sc["clip"]
    by_subject = subject_groups(config, missing)
    subject = next(iter(by_subject), "")
    if spec is not None:
        trial = spec.split("@", 1)[0]
        for s, (loo, split) in by_subject.items():
            if trial in [f"{g}/{t}" for g, ids in loo.items() for t in ids] + [f"{g}/{t}" for g, t in split.items()]:
                subject = s
    return spec, int(sc["seed"]), subject


def subject_showcase(config: dict, subject: str, missing=()) -> list:
    """What one subject's generator jobs show (:func:`animsynth.compare.runner.showcase_clip`): ``[clip spec, seed,
    required]``: the run's showcase clip where it is this subject's (required: a generator that cannot be built on it
    stops the run), else the subject's first clip (not required: its start alone then)."""
    spec, seed, owner = showcase(config, missing)
    return [spec if owner == subject else None, seed, owner == subject]


def unavailable(name: str) -> str:
    """Why generator ``name`` cannot run here ('' when it can).

    Only fairmotion can be missing: its package is installed apart from the stack (``python3 run.py``
    installs it with ``--no-deps``; docs/compare/generators.md). Checked without importing it (the workflow parses
    this in every job): a package that is installed but whose motion graph cannot be imported stops
    the fairmotion job with :class:`animsynth.compare.generators.fairmotion_peer.FairmotionUnavailable`.
    """
    import importlib.util

    if name in ("fairmotion", "fairmotion_fixed") and importlib.util.find_spec("fairmotion") is None:
        return ("fairmotion is not installed (python3 run.py installs fairmotion 0.0.4 with --no-deps; "
                "animsynth.compare.generators.fairmotion_peer.INSTALL_COMMAND)")
    return ""


def user_generators(config: dict) -> dict:
    """``{row name: "path/to/file.py:ClassName"}`` of ``compare.user_generators`` (a researcher's own classes,
    :mod:`animsynth.compare.generators.user`), in config order."""
    return dict(config["compare"].get("user_generators") or {})


def generator_order(config: dict) -> list[str]:
    """The order of the tables: ``compare.generators``, then the user generators."""
    return list(config["compare"]["generators"]) + list(user_generators(config))


def run_generators(config: dict) -> tuple[list[str], dict]:
    """``(generators that run, {generator left out: reason})``: fairmotion is left out when its package is
    not installed here (:func:`unavailable`); the user generators run after the family's own (a user
    generator that cannot run is found out by its job, which still writes its files: docs/compare/own_generator.md)."""
    run, left = [], {}
    for g in config["compare"]["generators"]:
        why = unavailable(g)
        if why:
            left[g] = why
        else:
            run.append(g)
    return run + list(user_generators(config)), left


def user_job_cfg(config: dict, name: str) -> dict:
    """What a user generator's job adds to the shared keys: its spec, as the job's rerun trigger the SHA-256 of its
    file (:func:`animsynth.compare.generators.user.file_sha256`: a changed file reruns that job alone), and how the class runs
    (``compare.user_timeout_s``, ``compare.user_process``)."""
    from .generators.user import file_sha256

    spec = user_generators(config)[name]
    cmp = config["compare"]
    return {"user_generators": {name: spec}, "user_file_sha256": file_sha256(spec),
            "user_timeout_s": cmp.get("user_timeout_s"), "user_process": cmp.get("user_process", True)}


#: the ``compare`` keys the clips job reads (the protocol: rate, start, lengths, temporal split, clips per subject,
#: database size)
CLIP_KEYS = ("fps", "context", "length", "min_length", "split_blocks", "max_clips_per_subject",
             "min_clips_per_subject", "max_database_s")
#: the ``compare`` keys every generator job reads
RUN_KEYS = ("seed", "seeds", "fps", "metrics", "transitions_per_s", "cost_guard")
#: each generator's own ``compare`` block (a changed block reruns only the jobs of the generators that read it)
GENERATOR_BLOCKS = {"delaunay": "field", "knn": "field", "isomap": "resequencing_graph",
                    "stisomap": "resequencing_graph", "motion_graph": "motion_graph", "fairmotion": "fairmotion",
                    "fairmotion_fixed": "fairmotion", "motion_matching": "motion_matching",
                    "motion_matching_pose": "motion_matching", "motion_matching_traj": "motion_matching",
                    "genmm": "genmm", "concat": "concat"}


def native_rates(config: dict) -> list[float]:
    """The native rates the clips are also prepared at: ``compare.fairmotion.native_fps`` when a fairmotion row is
    among ``compare.generators`` and the rate is set and differs from ``compare.fps`` (else none)."""
    from .generators.names import FAIRMOTION_ROWS

    cmp = config["compare"]
    rate = (cmp.get("fairmotion") or {}).get("native_fps")
    if rate is None or not set(FAIRMOTION_ROWS) & set(cmp["generators"]) or float(rate) == float(cmp["fps"]):
        return []
    return [float(rate)]


def clips_cfg(config: dict) -> dict:
    """The config the clips job reads (:data:`CLIP_KEYS` of the ``compare`` block), as ``native_fps`` the native
    rates its clips also carry (:func:`native_rates`), and the ``capture_check`` block (every trial is checked
    before clips are cut: :func:`animsynth.capture_check.check_capture`)."""
    return {**{k: config["compare"][k] for k in CLIP_KEYS}, "native_fps": native_rates(config),
            "capture_check": dict(config["capture_check"])}


def first_frames(config: dict) -> dict:
    """``{trial id: first_frame}`` of the trial records (the frames a file has before the parsed motion)."""
    return {str(t["id"]): int(t.get("first_frame", 0) or 0) for t in config["trials"]}


def job_cfg(config: dict, generator: str | None = None, budget: float | None = None) -> dict:
    """The config one generator job reads, built the same way for the workflow and the tests.

    Parameters
    ----------
    config : the whole (validated) config
    generator : a generator name: :data:`RUN_KEYS`, the generator's own block (:data:`GENERATOR_BLOCKS`) and,
        for ``stisomap``, the re-sequencing study's ST-Isomap parameters (``resequencing.stisomap``: the compare
        family runs that study's method); ``None``: the config of every generator at once (each block and
        ``stisomap``), for a caller that fits several generators from one config
    budget : a transition budget of the budget sweep (``compare.budget_sweep``): ``transitions_per_s`` set to it
        and ``compare.budget_sweep_seeds`` seeds (at most ``compare.seeds``); without one, a generator's config has
        ``long_track``: its long-track settings (:func:`animsynth.compare.long_track.long_settings`, ``None``: off)

    Returns
    -------
    dict, the keys in that order (the workflow hands it to the job as a param: the same dict reruns nothing)
    """
    cmp = config["compare"]
    cfg = {k: cmp[k] for k in RUN_KEYS}
    names = list(GENERATOR_BLOCKS) if generator is None else [generator]
    for name in names:
        block = GENERATOR_BLOCKS.get(name)
        if block:
            cfg[block] = cmp[block]
    if "stisomap" in names:
        cfg["stisomap"] = dict(config["resequencing"]["stisomap"])
    if generator is not None and generator in user_generators(config):
        cfg.update(user_job_cfg(config, generator))
    if budget is not None:
        cfg["transitions_per_s"] = float(budget)
        cfg["seeds"] = min(int(cmp["seeds"]), int(cmp["budget_sweep_seeds"]))
    elif generator is not None:
        from .long_track import long_settings

        # the row's own long-track settings (its seeds resolved): another row's seeds rerun nothing here
        cfg["long_track"] = long_settings(cmp.get("long_track"), generator)
    return cfg


def check(config: dict) -> None:
    """Raise :class:`ConfigError` naming the key for values the schema cannot check (each step below names what it
    checks)."""
    cmp = config["compare"]
    _warn_unknown_clip_sources(config)
    _check_user_generator_names(config)
    check_subject_sets(config)
    _check_clip_sources(config)
    check_trial_rates(config)  # a user's trials: each at its own rate (a BVH file's Frame Time)
    _check_clip_sizes(cmp)
    _check_generator_blocks(cmp)
    _check_showcase_and_window(config)
    from .claims import check_claims

    check_claims(config)  # the declared claims against the metric table and the configured rows


def _warn_unknown_clip_sources(config: dict) -> None:
    """A subset or re-sequencing key the run does not have is left out with a warning (the demo default names r1; a
    user's config with other subsets must still run every family), never an error that stops the other families."""
    cmp = config["compare"]
    have = {k for k, v in config["subsets"].items() if v}
    for s in cmp["subsets"] or []:
        if s not in have:
            log.warning("config key 'compare.subsets': %r is not a subset of this run (%s): left out of the "
                        "comparison", s, sorted(have))
    for d in cmp["resequencing"] or []:
        if d not in config["resequencing_trials"]:
            log.warning("config key 'compare.resequencing': %r is not a key of resequencing_trials (%s): left out "
                        "of the comparison", d, sorted(config["resequencing_trials"]))


def _check_user_generator_names(config: dict) -> None:
    """A user generator's name is none of the family's and no other file's; its spec parses."""
    from .generators.names import GENERATORS
    from .generators.user import parse_spec

    for name, spec in user_generators(config).items():
        if name in GENERATORS:
            raise ConfigError(f"config key 'compare.user_generators.{name}': {name!r} is the name of one of the "
                              "family's generators; give your generator another name")
        if name.endswith(("_timing", "_showcase", "_long")):
            raise ConfigError(f"config key 'compare.user_generators.{name}': a name may not end in _timing, "
                              "_showcase or _long (the names of a generator's other files: concat_long.csv is "
                              "concat's long track)")
        try:
            parse_spec(spec)
        except ValueError as exc:
            raise ConfigError(f"config key 'compare.user_generators.{name}': {exc}") from None


def _check_clip_sources(config: dict) -> None:
    """There are clips to compare, every subset can leave one out, and AMC trials' rate divides into compare.fps."""
    cmp = config["compare"]
    subsets, reseq = groups(config)
    if not subsets and not reseq:
        raise ConfigError("config keys 'compare.subsets' and 'compare.resequencing': no clip to compare")
    for s, ids in subsets.items():
        if len(ids) < 2:
            raise ConfigError(f"config key 'compare.subsets': subset {s!r} has {len(ids)} trial; leave one out "
                              "needs at least 2")
    if config["mocap_source"] != "user":  # AMC trials run at the config's fps (BVH files carry their own)
        ratio = float(config["fps"]) / float(cmp["fps"])
        if abs(ratio - round(ratio)) > 1e-6 or round(ratio) < 1:
            raise ConfigError(f"config key 'compare.fps': {cmp['fps']} must be the trials' rate (fps: "
                              f"{config['fps']}) divided by a whole number")


def _check_clip_sizes(cmp: dict) -> None:
    """The clip counts and lengths are consistent: a subject can enter the tests, a clip is at least its minimum."""
    cap = cmp.get("max_clips_per_subject")
    if cap is not None and cmp["min_clips_per_subject"] > cap:
        raise ConfigError(f"config key 'compare.min_clips_per_subject': {cmp['min_clips_per_subject']} exceeds "
                          f"compare.max_clips_per_subject ({cap}): no subject could enter the declared tests")
    if cmp["min_length"] > cmp["length"]:
        raise ConfigError(f"config key 'compare.min_length': {cmp['min_length']} exceeds compare.length "
                          f"({cmp['length']})")


def _check_generator_blocks(cmp: dict) -> None:
    """Each generator block's values fit together (segments, blends, strides, future times, weights, patches)."""
    c = cmp["concat"]
    if c["min_segment_s"] > c["max_segment_s"]:
        raise ConfigError(f"config key 'compare.concat.min_segment_s': {c['min_segment_s']} exceeds "
                          f"compare.concat.max_segment_s ({c['max_segment_s']})")
    mg = cmp["motion_graph"]
    if mg["blend"] is not None and mg["blend"] > mg["window"]:
        raise ConfigError(f"config key 'compare.motion_graph.blend': {mg['blend']} exceeds the window "
                          f"({mg['window']} frames)")
    _check_fairmotion_block(cmp["fairmotion"])
    mm = cmp["motion_matching"]
    fut = [float(x) for x in mm["future_s"]]
    if any(b <= a for a, b in zip(fut, fut[1:])):
        raise ConfigError(f"config key 'compare.motion_matching.future_s': {mm['future_s']} must increase")
    if not any(float(w) > 0 for w in mm["weights"][:3]):
        raise ConfigError(f"config key 'compare.motion_matching.weights': the pose groups' weights (the first three, "
                          f"{mm['weights'][:3]}) are all 0: motion_matching_pose would match on nothing")
    gm = cmp["genmm"]
    if gm["patch_size"] % 2 == 0:
        raise ConfigError(f"config key 'compare.genmm.patch_size': {gm['patch_size']} must be odd (a patch is "
                          "centred on its frame)")
    if "genmm" in cmp["generators"] and gm["patch_size"] > cmp["context"] + cmp["min_length"]:
        raise ConfigError(f"config key 'compare.genmm.patch_size': {gm['patch_size']} frames exceed "
                          f"compare.context + compare.min_length ({cmp['context']} + {cmp['min_length']}): a short "
                          "clip's start and continuation would hold no patch")


def _check_fairmotion_block(fm: dict) -> None:
    """fairmotion's blend is below its base, its comparison window at least the blend, its stride at most the base."""
    if not fm["blend"] < fm["base"]:
        raise ConfigError(f"config key 'compare.fairmotion.blend': {fm['blend']} must be below base ({fm['base']})")
    if fm["compare"] < fm["blend"]:
        raise ConfigError(f"config key 'compare.fairmotion.compare': {fm['compare']} must be at least blend "
                          f"({fm['blend']})")
    if fm["stride"] is not None and fm["stride"] > fm["base"]:
        raise ConfigError(f"config key 'compare.fairmotion.stride': {fm['stride']} exceeds base ({fm['base']})")


def _check_showcase_and_window(config: dict) -> None:
    """The showcase clip is a held-out trial and its seed one of the run's; the metrics' window fits a short clip."""
    cmp = config["compare"]
    sc = cmp["showcase"]
    if sc["clip"] is not None and sc["clip"].split("@", 1)[0] not in held_out_trials(config):
        raise ConfigError(f"config key 'compare.showcase.clip': {sc['clip']!r} is not a held-out trial of this run "
                          f"(one of {held_out_trials(config)}, optionally with @<frame> of one of its clips)")
    if sc["seed"] >= cmp["seeds"]:
        raise ConfigError(f"config key 'compare.showcase.seed': seed index {sc['seed']} but compare.seeds is "
                          f"{cmp['seeds']}")
    if cmp["metrics"]["window"] > cmp["min_length"]:
        raise ConfigError(f"config key 'compare.metrics.window': {cmp['metrics']['window']} frames exceed "
                          f"compare.min_length ({cmp['min_length']}): a short clip would have no window")


def check_subject_sets(config: dict) -> None:
    """Refuse a ``compare.subjects`` set that is not one subject's trials with records: a name taken by a subset or
    re-sequencing clip, a trial without a record in ``trials``, or trials of two subjects (their records'
    ``subject``) in one set, which would count two independent units as one.

    Raises
    ------
    ConfigError
        naming ``compare.subjects.<set>``
    """
    from ..config import ADD_TRIAL

    records = {t["id"]: t for t in config["trials"]}
    taken = set(config["subsets"]) | set(config["resequencing_trials"])
    for name, ids in subject_sets(config).items():
        key = f"config key 'compare.subjects.{name}'"
        if name in taken:
            raise ConfigError(f"{key}: {name!r} is the name of a subset or re-sequencing clip; give the set another "
                              "name")
        bad = [t for t in ids if t not in records]
        if bad:
            raise ConfigError(f"{key}: trial(s) {', '.join(map(repr, bad))} have no record in 'trials' (every trial "
                              f"of the comparison is fetched and parsed); {ADD_TRIAL}")
        subjects = {}
        for t in ids:
            subjects.setdefault(str(records[t]["subject"]), []).append(t)
        if len(subjects) > 1:
            parts = "; ".join(f"subject {s}: {', '.join(ts)}" for s, ts in subjects.items())
            raise ConfigError(f"{key}: mixes trials of {len(subjects)} subjects ({parts}); a set is one subject "
                              "(one independent unit of the verdicts): give each subject a set of its own")


def _flow(values) -> str:
    """``[a, b]`` as the YAML of a config file writes a list."""
    return "[" + ", ".join(str(v) for v in values) + "]"


def left_out(config: dict) -> list[str]:
    """What the comparison leaves out of this run's data, one line each naming the config key that does it.

    A subset of the run (``subsets``) not named by ``compare.subsets`` and a re-sequencing clip
    (``resequencing_trials``) not named by ``compare.resequencing``; each line names the trials it holds. The
    workflow prints them at parse time on a user's data (``mocap_source: user``), where the demo's
    ``compare.subsets: [r1]`` would otherwise leave a user's other subsets out silently.
    """
    cmp = config["compare"]
    subsets = {k: list(v) for k, v in config["subsets"].items() if v}
    reseq = dict(config["resequencing_trials"])
    lines = []
    if cmp["subsets"] is not None:
        for s, ids in subsets.items():
            if s not in cmp["subsets"]:
                lines.append(f"compare: subset {s!r} ({', '.join(ids)}) of this run left out by compare.subsets: "
                             f"{_flow(cmp['subsets'])} (set compare.subsets: null for every subset)")
    if cmp["resequencing"] is not None:
        for d, t in reseq.items():
            if d not in cmp["resequencing"]:
                lines.append(f"compare: re-sequencing clip {d!r} ({t}) of this run left out by compare.resequencing: "
                             f"{_flow(cmp['resequencing'])} (set compare.resequencing: null for every clip of "
                             "resequencing_trials)")
    return lines


def trial_rate(config: dict, trial: dict) -> tuple[float | None, str]:
    """``(frame rate, where it comes from)`` of one trial record as its parse job will read it.

    An ASF/AMC trial (and a synthetic or CMU one) runs at the config's ``fps``; a BVH trial at the rate of its
    file's ``Frame Time`` line (:func:`animsynth.io.bvh.bvh_frame_rate`: the header only, not the motion).
    ``(None, why)`` when the file cannot be read here (a URL ``data_dir``, a file not there yet): the clips job
    then checks the rate.
    """
    if "bvh" not in trial or "amc" in trial:
        return float(config["fps"]), f"fps: {config['fps']}"
    from ..config import resolve_inside
    from ..io.bvh import bvh_frame_rate

    root = config.get("cmu_mirror") if config["mocap_source"] == "cmu" else config.get("data_dir")
    if not root or "://" in str(root):
        return None, "its file is not local"
    try:
        path = resolve_inside(str(root), trial["bvh"], "bvh")
        return float(bvh_frame_rate(path)), f"the Frame Time of {path}"
    except (OSError, ValueError) as exc:
        return None, " ".join(str(exc).split())


def check_trial_rates(config: dict) -> None:
    """Refuse a ``compare.fps`` that is not a trial's rate divided by a whole number, for every trial the
    comparison uses (the clips job keeps every n-th frame, n = trial fps / compare.fps: a whole number).

    Only a user's data (``mocap_source: user``) is read here: the other sources' trials all run at ``fps``
    (checked by :func:`check`). A BVH file that cannot be read now is left to the clips job.

    Raises
    ------
    ConfigError
        naming ``compare.fps``, the first trial it does not fit and its rate, and the rates that fit every trial
        the comparison uses (:func:`common_rates`)
    """
    if config["mocap_source"] != "user":
        return
    want = float(config["compare"]["fps"])
    subsets, reseq = groups(config)
    used = list(dict.fromkeys([t for ids in subsets.values() for t in ids] + list(reseq.values())))
    records = {t["id"]: t for t in config["trials"]}
    rates = {}
    for tid in used:
        if tid in records:  # an unknown id: animsynth.config.check_config names it
            fps, where = trial_rate(config, records[tid])
            if fps is not None:
                rates[tid] = (fps, where)
    bad = [(tid, fps, where) for tid, (fps, where) in rates.items() if not _divides(fps, want)]
    if bad:
        tid, fps, where = bad[0]
        fits = common_rates([f for f, _w in rates.values()])
        hint = (f"set compare.fps to one that fits every trial the comparison uses: {', '.join(fits)}" if fits
                else "no rate fits every trial the comparison uses (" + ", ".join(
                    sorted({f"{f:g}" for f, _w in rates.values()})) + " fps): leave the trials of another rate out "
                "of compare.subsets / compare.resequencing")
        more = f" (and {len(bad) - 1} more trial(s))" if len(bad) > 1 else ""
        raise ConfigError(f"config key 'compare.fps': {config['compare']['fps']} fps is not the rate of trial "
                          f"{tid!r} ({fps:g} fps, {where}){more} divided by a whole number (the comparison keeps "
                          f"every n-th frame); {hint}")


def _divides(fps: float, rate: float) -> bool:
    ratio = fps / rate
    return abs(ratio - round(ratio)) <= 1e-6 and round(ratio) >= 1


def common_rates(rates, most: int = 4) -> list[str]:
    """The working rates (whole frames per second, highest first, at most ``most``) that every rate of ``rates``
    divides by a whole number: e.g. 6 for files at 24, 30 and 120 fps."""
    rates = [float(r) for r in rates]
    if not rates:
        return []
    low = min(rates)
    out = []
    for n in range(1, int(low) + 1):
        r = low / n
        if abs(r - round(r)) < 1e-9 and all(_divides(f, r) for f in rates):
            out.append(f"{r:g}")
        if len(out) == most:
            break
    return out
