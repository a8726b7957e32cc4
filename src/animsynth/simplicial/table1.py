"""Gauch & Peters Table I for the data of a run: subsets, pose dimension, lengths, total nodes, and the
published lengths beside ours (``results/data/datasets.csv``).

The published lengths are read by :func:`animsynth.simplicial.settings.read_paper_table1`.
"""

from __future__ import annotations

import pandas as pd


def datasets_table(subsets: dict, motions: dict, source: str, paper: dict | None = None) -> pd.DataFrame:
    """Gauch & Peters Table I for the selected data.

    Parameters
    ----------
    subsets : name -> list of trial ids (in order)
    motions : trial id -> Motion
    source : ``synthetic``, ``cmu`` or ``user``
    paper : name -> list of published lengths (:func:`~animsynth.simplicial.settings.read_paper_table1`), optional
        When given (even empty) the table gets ``paper_lengths``, ``paper_total_nodes``,
        ``total_nodes_minus_paper`` (ours - paper)
        and ``length_match`` (which trials match the paper's length at the same
        position, and which stand in for another length); empty for subsets the
        paper does not list.
    """
    rows = []
    for name, ids in subsets.items():
        lengths = [motions[t].n_frames for t in ids]
        dims = {motions[t].without_root().shape[1] for t in ids}
        if len(dims) != 1:
            raise ValueError(f"subset {name!r} mixes trials with different DOF counts {sorted(dims)}")
        rows.append(
            {
                "dataset": name,
                "source": source,
                "trials": " ".join(ids),
                "dims": dims.pop(),
                "n_sequences": len(ids),
                "lengths": " ".join(str(n) for n in lengths),
                "total_nodes": int(sum(lengths)),
            }
        )
        if paper is not None:
            pl = paper.get(name)
            rows[-1]["paper_lengths"] = " ".join(map(str, pl)) if pl else ""
            rows[-1]["paper_total_nodes"] = int(sum(pl)) if pl else None
            rows[-1]["total_nodes_minus_paper"] = int(sum(lengths)) - int(sum(pl)) if pl else None
            rows[-1]["length_match"] = length_match(ids, lengths, pl) if pl else ""
    cols = ["dataset", "source", "trials", "dims", "n_sequences", "lengths", "total_nodes"]
    if paper is not None:
        cols += ["paper_lengths", "paper_total_nodes", "total_nodes_minus_paper", "length_match"]
    return pd.DataFrame(rows, columns=cols)


def length_match(ids, lengths, paper_lengths) -> str:
    """``all N match`` or which trials match the published lengths (same position) and which stand in."""
    same = [f"{t} ({n})" for t, n, p in zip(ids, lengths, paper_lengths) if n == p]
    other = [f"{t} ({n}) for {p}" for t, n, p in zip(ids, lengths, paper_lengths) if n != p]
    if len(paper_lengths) != len(ids):
        other.append(f"paper lists {len(paper_lengths)} sequences, we use {len(ids)}")
    if not other:
        return f"all {len(ids)} match"
    return ("match: " + ", ".join(same) + "; " if same else "") + "stand-ins: " + ", ".join(other)


__all__ = ["datasets_table", "length_match"]
