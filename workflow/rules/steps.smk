# Every step's rules, made from the step registry (synergrasp.steps.STEPS), in the order the
# steps run: each rule is named as in the registry, reads the inputs its registry entry names
# (and the code its script imports), writes the registry's outputs, log and benchmark, is
# handed what its registry entry says (the part of the configuration its step reads), and
# runs workflow/scripts/<rule>.py. Nothing of a rule is written by hand; a new step is one registry
# entry (docs/design.md, "Adding a step").
#
# A function, not a loop's body: Snakemake evaluates the script's path again when the job
# runs, so it must read this call's name, not a loop variable's last value. snakefmt cannot
# parse a function making a rule, hence fmt off around it.
# fmt: off
def step_rule(_rule):
    rule:
        name:
            _rule
        input:
            **W.inputs(_rule),
        output:
            **RuleFiles(_rule).snakemake_outputs(report, directory, temp, _ARCHIVE),
        log:
            RuleFiles(_rule).log(),
        benchmark:
            RuleFiles(_rule).benchmark()
        threads: rule_costs()[_rule].threads
        resources:
            **W.resources(_rule),
        params:
            **W.params(_rule),
        script:
            f"../scripts/{_rule}.py"
# fmt: on
for _name in rule_costs():
    step_rule(_name)
