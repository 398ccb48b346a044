"""Grasp-force optimisation of one shard of an object's poses, for every synergy set."""
from contextlib import redirect_stderr

import numpy as np
import pandas as pd

from synergrasp.config import step_params
from synergrasp.hand.synergies import load_synergies
from synergrasp.optimisation.batched import optimise_grasps
from synergrasp.simulation.contacts import read_grasps

with open(snakemake.log[0], "w") as log, redirect_stderr(log):
    opt = step_params(snakemake.params.cfg, "optimise", snakemake.wildcards.object)
    contacts = pd.read_parquet(snakemake.input.contacts)
    shard = contacts.iloc[np.array_split(np.arange(len(contacts)), opt.pose_shards)[int(snakemake.wildcards.shard)]]
    synergies = load_synergies(opt.synergies)
    result = optimise_grasps(read_grasps(shard), synergies.matrix, list(opt.sets.values()), opt.gfo)
    table = pd.DataFrame(result)
    poses = shard.iloc[table["pose"].to_numpy()]
    table.insert(0, "object", snakemake.wildcards.object)
    table["pose"] = poses["pose"].to_numpy()
    table.insert(2, "alpha_deg", poses["alpha_deg"].to_numpy())
    table.insert(3, "beta_deg", poses["beta_deg"].to_numpy())
    table.to_parquet(snakemake.output[0], index=False)
