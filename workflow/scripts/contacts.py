"""The contacts that count: only those of the closure that carry load (closure.dynamic.unloaded_contacts: drop)."""

from synergrasp import table_contracts
from synergrasp.job_log import job_log
from synergrasp.simulation.contacts import ContactsParams, load_carrying_contacts

with job_log(snakemake.log[0]):
    params = ContactsParams.from_config(snakemake.params.cfg)
    closure = table_contracts.read(table_contracts.CONTACTS, snakemake.input.contacts)
    table_contracts.write(table_contracts.CONTACTS, load_carrying_contacts(closure, params.load_threshold_N), snakemake.output[0])
