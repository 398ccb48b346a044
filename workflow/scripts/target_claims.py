"""The study's claims at every scored target of one object's placement search."""

from synergrasp import table_contracts
from synergrasp.analysis.periods import alpha_period_deg
from synergrasp.analysis.target_claims import TargetClaimsParams, claims_at_targets
from synergrasp.hand.kinematics import load_hand
from synergrasp.hand.synergies import load_synergies
from synergrasp.job_log import job_log

with job_log(snakemake.log[0]):
    p = TargetClaimsParams.from_config(snakemake.params.cfg, snakemake.wildcards.object)
    hand = load_hand(p.search.hand)
    synergies = load_synergies(p.search.synergies, joint_names=hand.joint_names)
    period = alpha_period_deg(p.search.placement, p.search.object.shape, hand.palm_normal)
    placement = table_contracts.read_csv(table_contracts.PLACEMENT, snakemake.input.placement)
    claims = claims_at_targets(hand, synergies, p, period, placement, processes=snakemake.threads)
    table_contracts.write(table_contracts.TARGET_CLAIMS, claims, snakemake.output[0])
