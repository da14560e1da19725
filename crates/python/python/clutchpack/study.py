"""Studies from Python: run a study file's cases (all, or one shard) into a folder and merge
the parts into the results table, as ``clutchpack study run`` and ``study merge`` do.

    >>> import clutchpack.study
    >>> clutchpack.study.run("studies/paper-mc-1000.toml", "out/mc", jobs=2)
    >>> df = clutchpack.study.merge("out/mc")       # one row per case and body
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from typing import Optional, Union

import pandas as pd

from . import _clutchpack
from ._args import _integer

PathLike = Union[str, "os.PathLike[str]"]

__all__ = ["ShardRun", "run", "merge"]


@dataclass
class ShardRun:
    """What a shard's run did: its part file, its cases, those skipped (already in the part),
    run now and failed (a failed case is a row with its message), and whether every case of
    the shard is done."""

    part: str
    cases: int
    skipped: int
    ran: int
    failed: int
    complete: bool


def run(
    study: PathLike, out: PathLike, jobs: Optional[int] = None, shard: int = 0, shards: int = 1
) -> ShardRun:
    """Runs shard ``shard`` of ``shards`` of the study file ``study`` into the folder ``out``
    on ``jobs`` threads (default: every core); a rerun runs only the cases its part lacks.
    A bad study file raises ``ValueError`` with every problem at its key."""
    jobs = None if jobs is None else _integer("jobs", jobs, 1)
    shards = _integer("shards", shards, 1)
    shard = _integer("shard", shard, 0)
    if shard >= shards:
        raise ValueError(f"shard = {shard}: expected a shard index below shards = {shards}")
    p, cases, skipped, ran, failed, complete = _clutchpack.study_run(
        os.fspath(study), os.fspath(out), jobs=jobs, shard=shard, shards=shards
    )
    return ShardRun(os.fspath(p), cases, skipped, ran, failed, complete)


def merge(dir: PathLike, plot_format: str = "png") -> pd.DataFrame:
    """Merges the parts in ``dir`` (every shard must have run) into ``results.csv``,
    ``summary.csv``, ``results.parquet`` and ``main-effects.<plot_format>``; returns the
    results table (one row per case and body: the factors' values, the statistics in N, the
    fatigue columns)."""
    csv = _clutchpack.study_merge(os.fspath(dir), plot_format=plot_format)
    return pd.read_csv(os.fspath(csv))
