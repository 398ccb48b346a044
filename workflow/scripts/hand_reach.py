"""The hand's reach table and its side view (docs/hand_reach.md): per finger the reach along S1
and in any posture, d_max and the aperture; the study's boxes beside it."""

from synergrasp import table_contracts
from synergrasp.figures.hand_reach import figure_hand_reach
from synergrasp.hand.kinematics import load_hand
from synergrasp.hand.synergies import load_synergies
from synergrasp.job_log import job_log
from synergrasp.simulation.reach import HandReachStepParams, path_postures, read_hand_reach

with job_log(snakemake.log[0]):
    params = HandReachStepParams.from_config(snakemake.params.cfg)
    hand = load_hand(params.hand)
    synergies = load_synergies(params.synergies, joint_names=hand.joint_names)
    reach = read_hand_reach(snakemake.input.reach, hand)
    table_contracts.write_study_table(
        reach.table[list(table_contracts.HAND_REACH.names)],
        snakemake.output.csv,
        snakemake.output.md,
        title=f"Hand reach (palm face at x = {reach.palm_face_mm:g} mm; "
        f"d_max {reach.d_max_mm:g} mm, aperture {reach.aperture_mm:.1f} mm)",
    )
    figure_hand_reach(
        hand,
        path_postures(hand, synergies),
        reach,
        params.objects,
        params.reach.posture_steps,
        snakemake.output.png,
        snakemake.output.pdf,
    )
