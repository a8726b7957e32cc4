"""A workflow job imports the library before it does any work: importing a family package must not import the
heavy libraries (numba, scikit-learn, scipy.stats, matplotlib) until a name that needs them is used."""

from __future__ import annotations

import subprocess
import sys

from animsynth.families import paper_families

from conftest import SAFETY_TIMEOUT

HEAVY = ("numba", "sklearn", "scipy.stats", "matplotlib")


def _modules_after(code: str, names: tuple) -> set[str]:
    """Which of ``names`` are in ``sys.modules`` after ``code`` runs in a fresh interpreter (and what ``code``
    prints)."""
    probe = code + "\nimport sys\nprint(' '.join(m for m in " + repr(names) + " if m in sys.modules))"
    res = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, timeout=SAFETY_TIMEOUT)
    assert res.returncode == 0, res.stderr[-2000:]
    return set(res.stdout.split())


def _loaded_after(code: str) -> set[str]:
    """The heavy libraries (:data:`HEAVY`) loaded after ``code`` runs in a fresh interpreter."""
    return _modules_after(code, HEAVY)


def test_family_packages_import_no_heavy_library():
    modules = [f"animsynth.{name}" for name in (*paper_families(), "io", "motion")]
    assert _loaded_after("import " + ", ".join(modules)) == set()


def test_a_name_loads_its_module_on_first_use():
    # the lazy export really imports the module behind the name; scikit-learn loads when a fit needs it
    assert _modules_after("from animsynth.simplicial import run_fold", ("animsynth.simplicial.folds",))
    assert _modules_after("from animsynth.resequencing import STIsomap", ("animsynth.resequencing.embedding",))
    assert "sklearn" in _modules_after("from animsynth.simplicial.generator import fit_pca\nimport numpy as np\n"
                                       "fit_pca([np.random.default_rng(0).normal(size=(20, 6))], 2)", ("sklearn",))


def test_the_jobs_that_fit_nothing_import_no_scikit_learn():
    # the simplicial tables, summary and figures jobs and the re-sequencing path, explain and table jobs read what
    # the fitting jobs wrote: their modules load scikit-learn only in the functions that fit (PCA, kernel PCA)
    loaded = _modules_after("import animsynth.simplicial.jobs, animsynth.resequencing.jobs", ("sklearn",))
    assert loaded == set()


def test_the_metric_table_imports_no_heavy_library():
    # the tables, verdicts and figures jobs read the records, collected from the measure modules: those import
    # numpy and the kinematics at module level, and what else a computation needs on its first call
    assert _loaded_after("import animsynth.compare.measures.metric_table") == set()


def test_the_record_module_imports_no_measure():
    # a measure module imports the record module for its records: no cycle back through the table or a measure
    loaded = _loaded_after("import animsynth.compare.measures.metric_record, sys\n"
                           "print(' '.join(m for m in sys.modules if m.startswith('animsynth.compare.measures.')))\n"
                           "print('numpy' if 'numpy' in sys.modules else '')")
    assert loaded == {"animsynth.compare.measures.metric_record"}


def test_a_download_job_imports_no_numpy():
    # a download job copies a file and checks its hash: the trial readers (numpy, scipy) load only to parse one
    loaded = _loaded_after("import animsynth.data, animsynth.workflow_utils, sys\n"
                           "print(' '.join(m for m in ('numpy', 'scipy') if m in sys.modules))")
    assert loaded == set()


def test_the_modules_the_snakefile_loads_import_no_heavy_library():
    # every snakemake call (each SLURM job too) parses the Snakefile, which imports these for its config checks
    # and job lists: none may load a heavy library, and the data sources and the mesh settings not even scipy
    # (the mesh settings name the rig's joints from animsynth.rig_layout, not from the skinning module; the io
    # package loads a format's module on first use of its names)
    parse_time = ("animsynth.config", "animsynth.workflow_utils", "animsynth.families", "animsynth.sources",
                  "animsynth.meshdetail.settings", "animsynth.facegraph.settings", "animsynth.simplicial.settings",
                  "animsynth.resequencing.settings", "animsynth.compare.settings", "animsynth.compare.claims",
                  "animsynth.compare.long_track", "animsynth.resequencing.tables")
    assert _loaded_after("import " + ", ".join(parse_time)) == set()
    assert _modules_after("import animsynth.sources, animsynth.meshdetail.settings", ("scipy",)) == set()
