"""Independent groups of clips: the unit of every test of the side-by-side claims.

Clips are not independent: the leave-one-out clips of a subset share most of their database trials and the
subject, and a re-sequencing clip may be a trial that a subset's clips use. :func:`independent_groups` joins
clips that share a subject (or a subset and a subject) and every trial (held out or in a database);
:data:`GROUPINGS` names the groupings (``compare.verdicts.grouping``) as the evidence words them.
"""

from __future__ import annotations

import re

import pandas as pd

__all__ = ["GROUPINGS", "independent_groups", "clip_groups"]

_TRIAL = re.compile(r"\d+_\d+")
#: how the evidence names each grouping (``compare.verdicts.grouping``)
GROUPINGS = {
    "subject": "subject, joined where clips share a trial (held out or in a database)",
    "subset_subject": ("subset (or re-sequencing dataset) x subject, joined where clips share a trial (held out or "
                       "in a database)"),
}


def independent_groups(clips: pd.DataFrame, by: str = "subject") -> dict:
    """``{clip: group label}`` from the clips table (``clip``, ``group``, ``held_out``, ``database``, optionally
    ``subject``).

    A clip's trials are its held-out trial and its database trials (CMU ids ``<subject>_<trial>`` found in the
    clip id and the ``held_out`` and ``database`` columns; other names: the clip's trial and the database's
    names); its subject is the ``subject`` column (the trial record's ``subject``, as the protocol counts clips per
    subject), else the held-out trial's CMU subject (the text before ``_``; none for other names, so the subset
    alone makes the group). ``by="subject"``: the clips of one subject form a group (a clip without a
    subject: its subset); ``by="subset_subject"``: the clips of one subset and subject. Groups sharing a trial
    are joined. The label names the subsets / datasets joined (``r1 + run``) and, when one subset holds several
    groups, the subject; by subject, ``subject 35 (w1, r1, run, walk)``.
    """
    if by not in GROUPINGS:
        raise ValueError(f"config key 'compare.verdicts.grouping': {by!r} is not one of {list(GROUPINGS)}")
    rows = list(clips.itertuples(index=False))
    trials, base = {}, {}
    for r in rows:
        own = str(r.clip).split("/", 1)[-1].split("@", 1)[0]  # the held-out trial (a clip id may add @<frame>)
        text = f"{own} {r.held_out} {r.database}"
        ts = set(_TRIAL.findall(text))
        if not ts:  # not CMU ids: the clip's trial and the database's names (without a temporal split's range)
            ts = {own} | {t for t in str(r.database).split() if t != "frames" and not re.fullmatch(r"\d+-\d+", t)}
        trials[r.clip] = ts
        declared = str(getattr(r, "subject", "") or "").strip()
        held = _TRIAL.findall(own) or _TRIAL.findall(str(r.held_out))
        # the trial record's subject (clips.csv's column) first; else a CMU id's; none: the subset is the group
        subject = declared if declared and declared != "nan" else held[0].split("_")[0] if held else ""
        base[r.clip] = ("", subject) if by == "subject" and subject else (str(r.group), subject)
    parent = {k: k for k in set(base.values())}

    def find(x):
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x

    owner = {}
    for r in rows:
        for t in trials[r.clip]:
            if t in owner:
                parent[find(base[r.clip])] = find(owner[t])
            else:
                owner[t] = base[r.clip]
    members = {}
    for r in rows:
        members.setdefault(find(base[r.clip]), []).append(base[r.clip])
    per_subset = {}
    for g, s in set(base.values()):
        per_subset[g] = per_subset.get(g, 0) + 1
    labels = {}
    subsets = {}
    for r in rows:
        subsets.setdefault(find(base[r.clip]), []).append(str(r.group))
    for root, keys in members.items():
        keys = list(dict.fromkeys(keys))
        if by == "subject" and any(not g for g, _s in keys):
            subj = " + ".join(dict.fromkeys(f"subject {s}" for g, s in keys if not g))
            others = [g for g, _s in keys if g]
            labels[root] = f"{subj} ({', '.join(dict.fromkeys(subsets[root] + others))})"
            continue
        parts = [g if per_subset[g] == 1 else f"{g} subject {s}" for g, s in keys]
        labels[root] = " + ".join(dict.fromkeys(parts))
    return {r.clip: labels[find(base[r.clip])] for r in rows}


def clip_groups(metrics: pd.DataFrame, clips: pd.DataFrame | None, vc: dict) -> dict:
    """``{clip: group label}``: :func:`independent_groups` of ``clips`` (by ``vc["grouping"]``) when it has the
    columns it needs, else each clip's subset (the ``group`` column of ``metrics``)."""
    if clips is not None and {"clip", "group", "held_out", "database"} <= set(clips.columns):
        return independent_groups(clips, vc.get("grouping", "subject"))
    return dict(metrics.drop_duplicates("clip").set_index("clip")["group"])
