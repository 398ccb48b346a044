"""Fig. 1: the hand along each of the first seven synergies, sigma = -1, 0, +1."""

from synergrasp.figures.fig1_fig2_postures_grasps import Fig1Params, figure_synergy_postures
from synergrasp.hand.kinematics import load_hand
from synergrasp.hand.synergies import load_synergies
from synergrasp.job_log import job_log

with job_log(snakemake.log[0]):
    params = Fig1Params.from_config(snakemake.params.cfg)
    hand = load_hand(params.hand)
    synergies = load_synergies(params.synergies, joint_names=hand.joint_names)
    figure_synergy_postures(
        hand, synergies, snakemake.output.png, snakemake.output.pdf, n_synergies=min(7, synergies.matrix.shape[1])
    )
