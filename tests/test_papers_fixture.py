"""tests/papers/ (the published tables the tiny run sees at ../shared/papers) is a faithful copy."""

import pandas as pd
import pytest

from conftest import PAPERS, REPO

SHARED_PAPERS = REPO.parent / "shared" / "papers"


def test_fixture_holds_every_table_the_default_config_reads():
    import yaml

    cfg = yaml.safe_load((REPO / "config" / "config.yaml").read_text())
    paths = [cfg["simplicial"]["paper_table2"], cfg["simplicial"]["paper_table1"], cfg["facegraph"]["paper_table1"],
             *cfg["resequencing"]["published"].values()]
    assert len(paths) == 5 and all(p.startswith("../shared/papers/") for p in paths), paths
    for p in paths:
        assert (PAPERS / p.rsplit("/", 1)[1]).is_file(), p


@pytest.mark.parametrize("name", sorted(p.name for p in PAPERS.glob("*.csv")))
def test_fixture_table_equals_the_shared_one(name):
    if not (SHARED_PAPERS / name).is_file():
        pytest.skip(f"{SHARED_PAPERS / name} is absent (it lives in ../shared, never in the repo)")
    ours, shared = pd.read_csv(PAPERS / name), pd.read_csv(SHARED_PAPERS / name)
    assert list(ours.columns) == list(shared.columns)
    pd.testing.assert_frame_equal(ours, shared)
