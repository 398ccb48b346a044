"""The hand's reach, once per hand (docs/hand_reach.md): per finger the reach along S1 and in
any posture, d_max and the aperture; what the placement search's gate reads."""

from synergrasp import table_contracts
from synergrasp.hand.kinematics import load_hand
from synergrasp.hand.synergies import load_synergies
from synergrasp.job_log import job_log
from synergrasp.simulation.reach import ReachStepParams, hand_reach

with job_log(snakemake.log[0]):
    params = ReachStepParams.from_config(snakemake.params.cfg)
    hand = load_hand(params.hand)
    reach = hand_reach(hand, load_synergies(params.synergies, joint_names=hand.joint_names), params.closure, params.reach)
    table_contracts.write(table_contracts.HAND_REACH, reach.table[list(table_contracts.HAND_REACH.names)], snakemake.output[0])
