"""Fig. 2: representative simulated grasps of every object, chosen by rule from its contacts,
and the same grasps in 3-D: one page each with the full set's optimal forces, one shared plotly script."""

from synergrasp import table_contracts
from synergrasp.figures.fig1_fig2_postures_grasps import figure_example_grasps
from synergrasp.figures.grasp_3d import Grasps3dParams, fig2_scenes, write_grasp_pages
from synergrasp.hand.kinematics import load_hand
from synergrasp.hand.synergies import load_synergies
from synergrasp.job_log import job_log

with job_log(snakemake.log[0]):
    params = Grasps3dParams.from_config(snakemake.params.cfg)
    hand = load_hand(params.hand)
    contacts = [table_contracts.read(table_contracts.CONTACTS, path) for path in snakemake.input.contacts]
    figure_example_grasps(
        hand, params.objects, contacts, snakemake.output.png, snakemake.output.pdf, oppositions=params.oppositions(hand, contacts)
    )
    matrix = load_synergies(params.synergies, joint_names=hand.joint_names).matrix
    write_grasp_pages(snakemake.output.pages, fig2_scenes(hand, matrix, params, contacts), "The grasps of Fig. 2 in 3-D")
