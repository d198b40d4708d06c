"""Test order for pytest-xdist: the costliest files first, so no worker idles at the end.

``make test`` runs each stage on two workers with ``--dist loadfile``: a file's tests stay on
one worker, and files are handed out in the order of the collection (``make test`` passes
``--no-loadscope-reorder``; by default xdist would hand out first the files with the most
tests, which are cheap ones). A file of 100 s of CPU handed out last kept one worker busy
for its 100 s while the other had nothing left: the longest files go first, and the many
small ones fill the gaps (the longest-processing-time-first rule). ``HEAVIEST`` lists file
stems by CPU seconds measured on 2026-11-28 (unit tests, then notebooks; a notebook's
stem matches its solution and its pair). The order only decides when a file starts, never
whether it passes: a stale list costs a few seconds, nothing else. Loaded by the root
``conftest.py``.
"""

from __future__ import annotations

from pathlib import Path

import pytest

HEAVIEST = [
    "test_grading_corpus",             # 115 s of CPU
    "test_grading_cluster",            # 53
    "test_nb10_hints",                 # 46
    "test_cloth",                      # 44
    "test_nb10_flocking",              # 41
    "test_grading",                    # 36
    "10_flocking",                     # 27 (solution; its pair 18 + its answers)
    "test_nb09_particle_systems",      # 26
    "08_hair_chains",                  # 24
    "09_particle_systems",             # 23
    "test_grading_nbgrader",           # 24
    "11_cloth",                        # 22
    "14_rigid_bodies",                 # 20
    "06_forces",                       # 19
    "test_nb13_sph_liquids",           # 19
    "test_nb08_hair",                  # 19
    "03_stability",                    # 19
    "test_nb09_sixth_read",            # 18
    "13_sph_liquids",                  # 18
    "04_beyond_euler",                 # 18
    "test_clips",                      # 17
    "07_springs",                      # 17
    "test_nb12_constraints",           # 16
    "test_nb11_cloth",                 # 16
    "12_constraints_and_large_steps",  # 15
    "test_rigid_contact",              # 15
    "01_vector_fields",                # 14
    "02_forward_euler",                # 14
    "test_players",                    # 14
]
_RANK = {stem: rank for rank, stem in enumerate(HEAVIEST)}


def rank(path: Path) -> int:
    """Where a file goes: its place in :data:`HEAVIEST`, or after all of them."""
    return _RANK.get(Path(path).stem, len(HEAVIEST))


@pytest.hookimpl(trylast=True)
def pytest_collection_modifyitems(session, config, items):
    """Stable sort: the heaviest files first, each file's items in their own order (a
    notebook's cells, then its re-run, stay together and in order)."""
    items.sort(key=lambda item: rank(item.path))
