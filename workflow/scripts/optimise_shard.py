"""Grasp-force optimisation of one shard of an object's poses, for every synergy set."""

import numpy as np
import pandas as pd

from synergrasp.optimisation.batched import optimise_grasps
from synergrasp.simulation.contacts import read_grasps
from synergrasp.config import gfo_params
from synergrasp.hand.synergies import load_synergies
from synergrasp.job_log import job_log

with job_log(snakemake.log[0]):
    opt = snakemake.params.opt
    contacts = pd.read_parquet(snakemake.input.contacts)
    shard = contacts.iloc[np.array_split(np.arange(len(contacts)), snakemake.params.n_shards)[opt["shard"]]]
    synergies = load_synergies(opt["synergies"])
    result = optimise_grasps(read_grasps(shard), synergies.matrix, list(opt["sets"].values()),
                             gfo_params(opt["mechanics"], opt["mass_kg"]))
    table = pd.DataFrame(result)
    poses = shard.iloc[table["pose"].to_numpy()]
    table.insert(0, "object", snakemake.wildcards.object)
    table["pose"] = poses["pose"].to_numpy()
    table.insert(2, "alpha_deg", poses["alpha_deg"].to_numpy())
    table.insert(3, "beta_deg", poses["beta_deg"].to_numpy())
    table.to_parquet(snakemake.output[0], index=False)
