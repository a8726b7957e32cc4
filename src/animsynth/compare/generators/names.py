"""The comparison's row names: a leaf module (no import), so tables, plots, verdicts and settings read the names
without importing a generator (:mod:`.registry` builds the estimators)."""

__all__ = ["GENERATORS", "REFERENCES", "FAIRMOTION_ROWS", "DETERMINISTIC", "METHOD_ROWS"]

#: every generator name, in the order of the tables
GENERATORS = ("delaunay", "knn", "isomap", "stisomap", "motion_graph", "fairmotion", "fairmotion_fixed",
              "motion_matching", "motion_matching_pose", "motion_matching_traj", "genmm", "replay", "concat")
#: the generators that run fairmotion's package
FAIRMOTION_ROWS = ("fairmotion", "fairmotion_fixed")
#: the two reference rows (bounds, not methods)
REFERENCES = ("replay", "concat")
#: the generators whose motion the seed does not change (seed diversity 0)
DETERMINISTIC = ("motion_matching", "motion_matching_pose", "motion_matching_traj", "replay")
#: the rows that are variants of one method, run in one workflow job per subject (each row still fitted, timed and
#: scored on its own; fairmotion's rows have their own job with the budget sweep): {job: rows, in table order}
METHOD_ROWS = {"simplicial": ("delaunay", "knn"), "isomap": ("isomap", "stisomap"),
               "motion_matching": ("motion_matching", "motion_matching_pose", "motion_matching_traj"),
               "bounds": REFERENCES}
