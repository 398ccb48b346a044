"""The contacts that count: only those of the closure that carry load (closure.dynamic.unloaded_contacts: drop)."""

from synergrasp import tables
from synergrasp.job_log import job_log
from synergrasp.simulation.contacts import ContactsParams, load_carrying_contacts

with job_log(snakemake.log[0]):
    params = ContactsParams.from_config(snakemake.params.cfg)
    closure = tables.read(tables.CONTACTS, snakemake.input.contacts)
    tables.write(tables.CONTACTS, load_carrying_contacts(closure, params.load_threshold_N), snakemake.output[0])
