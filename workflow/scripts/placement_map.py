"""The placement map of one object: the search's score over its targets and grasps at the chosen one."""

from synergrasp import table_contracts
from synergrasp.figures.placement_map import figure_placement_map
from synergrasp.hand.kinematics import load_hand
from synergrasp.job_log import job_log
from synergrasp.optimisation.placement_search import SearchStepParams
from synergrasp.simulation.opposition import HandAxes, contacts_oppositions

with job_log(snakemake.log[0]):
    sim = SearchStepParams.from_config(snakemake.params.cfg, snakemake.wildcards.object)
    hand = load_hand(sim.hand)
    contacts = table_contracts.read(table_contracts.CONTACTS, snakemake.input.contacts)
    oppositions = dict(zip(contacts["pose"], contacts_oppositions(contacts, HandAxes.from_hand(hand), sim.opposition)))
    figure_placement_map(
        hand,
        sim.object,
        table_contracts.read_csv(table_contracts.PLACEMENT, snakemake.input.placement),
        contacts,
        sim.search.spacing_mm,
        snakemake.output.png,
        snakemake.output.pdf,
        oppositions=oppositions,
    )
