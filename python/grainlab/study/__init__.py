"""Campaigns of runs: the paper's Sec. 7 packing study and general parameter sweeps,
in local processes or on a Dask distributed cluster (docs/study.md)."""

from grainlab.study.campaign import (
    CampaignResult,
    Run,
    derive_seed,
    execute_run,
    make_run,
    read_table,
    run_campaign,
    write_table,
)
from grainlab.study.packing import MEASURES, PackingParams, measure, run_packing
from grainlab.study.paper import (
    HEXAGONAL_POROSITIES,
    IRREGULAR_POROSITIES,
    STUDY_COLUMNS,
    run_study,
    study_figures,
    study_runs,
)
from grainlab.study.plan import Plan, PlanError, load_plan, parse_plan, run_sweep

__all__ = [
    "HEXAGONAL_POROSITIES",
    "IRREGULAR_POROSITIES",
    "MEASURES",
    "STUDY_COLUMNS",
    "CampaignResult",
    "PackingParams",
    "Plan",
    "PlanError",
    "Run",
    "derive_seed",
    "execute_run",
    "load_plan",
    "make_run",
    "measure",
    "parse_plan",
    "read_table",
    "run_campaign",
    "run_packing",
    "run_study",
    "run_sweep",
    "study_figures",
    "study_runs",
    "write_table",
]
