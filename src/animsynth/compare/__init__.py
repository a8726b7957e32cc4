"""Beyond the papers: every motion generator of the project and the classic motion graph, side by side.

The same held-out clips (CMU's Gauch & Peters subsets by leave one out, the re-sequencing clips by a
temporal split), the same starts and seeds, one set of metrics (foot skating, seam jumps, smoothness,
LAFAN1's L2P / L2Q / NPSS, coverage, diversity, novelty) and the cost of each generator. This package
sits above the four families: it fits and runs their estimators (the registry, :mod:`.generators`)
to score them; no family imports it. Every generator, the graphs included, is a
:class:`animsynth.generator.Generator`: the interface (Generator, Database, root placement) has the one import
path :mod:`animsynth.generator`.

Modules
-------
generators      the registry: names -> estimators and their settings (``make_generator``), no method code:
                delaunay, knn (the simplicial family's FieldFollower), isomap, stisomap (the resequencing
                family's Resequencer), motion_graph, fairmotion, fairmotion_fixed, motion_matching,
                motion_matching_pose, motion_matching_traj (its query: the held-out future), genmm, replay, concat
references      the two reference rows: replay (the held-out capture) and concat (random segments)
motiongraph     the classic motion graph (Kovar, Gleicher & Pighin 2002)
point_clouds    joint-position point clouds and their closed-form floor alignment (both graphs compare with it)
motionmatching  motion matching with inertialization and foot locking (Clavet 2016; Holden et al. 2020)
genmm           generative motion matching (Li et al. 2023)
poses           the pose representation the two share; footlock: motion matching's foot locking and leg IK
fairmotion_peer fairmotion's motion graph on the same clips (the peer row), when it can be imported
fairmotion_fixes the named fixes of fairmotion's walk (the row fairmotion_fixed) and the recorder of its walk
metric_table    the metric table (``METRICS``: one record per column of metrics.csv, its unit, which way is
                better, what it needs, its label) and the selections that read it
metrics         the metrics (pure numpy; metres, m/s), gathered from positions (positions, facing, pose features),
                skating (foot skating), jumps (seam and per-frame jumps), smoothness, ground_truth (LAFAN1's
                L2P / L2Q / NPSS) and windows (coverage, diversity, novelty)
protocol        the protocol: held-out clips, their databases, starts and seeds; the clips file
scoring         one generated motion's metrics against its clip (``score``), also for motion files from any tool
                (``animsynth score``)
runner          one generator over every clip and seed, scored, with its cost; the showcase file
jobs            one function per workflow step (clips, one generator's run, the tables, the budget sweep, figures)
tables          the family's tables: medians and spreads, which generator wins which metric, cost, the sweep, the
                family's summary page
verdicts        the side-by-side claims, decided over clips x seeds
plots           metrics per generator with spreads, one skeleton strip per generator
settings        config checks and what the workflow reads of the ``compare`` block
user            your own generator in the comparison (``compare.user_generators``: a file and a class)
"""

from .._lazy import lazy_exports

# name -> module; imported on first use (the families' estimators, FieldFollower and Resequencer, are exported by
# their families: animsynth.simplicial, animsynth.resequencing)
_EXPORTS = {
    "Concat": ".references",
    "GENERATORS": ".generators",
    "METRICS": ".metric_table",
    "MotionGraph": ".motiongraph",
    "Replay": ".references",
    "make_generator": ".generators",
    "prepare_clips": ".protocol",
    "run_generator": ".runner",
}
__all__, __getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
