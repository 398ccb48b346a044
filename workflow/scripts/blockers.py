"""What blocks each synergy set of one object where the full set succeeds (docs/blockers.md)."""

from synergrasp import table_contracts
from synergrasp.analysis.blockers import BlockersParams, blockers_table
from synergrasp.hand.kinematics import load_hand
from synergrasp.hand.synergies import load_synergies
from synergrasp.job_log import job_log
from synergrasp.simulation.opposition import HandAxes

with job_log(snakemake.log[0]):
    params = BlockersParams.from_config(snakemake.params.cfg, snakemake.wildcards.object)
    hand = load_hand(params.hand)
    matrix = load_synergies(params.synergies, joint_names=hand.joint_names).matrix
    contacts = table_contracts.read(table_contracts.CONTACTS, snakemake.input.contacts)
    gfo = table_contracts.read(table_contracts.GFO, snakemake.input.gfo)
    table = blockers_table(contacts, gfo, hand.link_names, HandAxes.from_hand(hand), matrix, params)
    table_contracts.write(table_contracts.BLOCKERS, table, snakemake.output[0])
