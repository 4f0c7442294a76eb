# Generated rules: one per compute step of each paper's step list
# (src/netrepro/papers/<slug>/steps.yaml, read by netrepro.pipeline.stepspec), a `<rule>_shard` rule per
# sharded step, and the paper's result tables (PAPER_TABLES). Every paper of the registry gets its
# rules (the figures and the report pick the enabled ones); PAPER_TABLES lists the enabled papers.


for _slug in paper_slugs():
    _paper = step_list(_slug)
    _section = config.get(_slug, {})
    for _spec in _paper.steps:
        if _spec.shard:

            rule:
                name:
                    _spec.shard_rule
                input:
                    code=code(_spec.shard.func),
                output:
                    **_spec.shard.outputs,
                log:
                    _spec.shard_log,
                wildcard_constraints:
                    shard=r"\d+",
                conda:
                    CONDA_ENV
                threads: _spec.shard.threads or 1
                resources:
                    **_spec.shard.resources,
                params:
                    func=_spec.shard.func,
                    cfg=shard_params(_section, _spec),
                    rule=_spec.shard_rule,
                    io=io_json,
                shell:
                    step()

        rule:
            name:
                _spec.rule
            input:
                **step_inputs(_paper, _spec),
            output:
                **_spec.outputs,
            log:
                _spec.log,
            wildcard_constraints:
                **({_spec.over: "|".join(_paper.wildcards[_spec.over])} if _spec.over else {}),
            localrule: _spec.local
            conda:
                CONDA_ENV
            threads: _spec.threads or 1
            resources:
                **_spec.resources,
            params:
                func=_spec.func,
                cfg=(
                    over_params(_section, _spec)
                    if _spec.over
                    else as_json(compose_config(_section, _spec.config))
                ),
                rule=_spec.rule,
                io=io_json,
            shell:
                step()

    if enabled(_slug):
        PAPER_TABLES[_slug] = [step_output(_slug, ref) for ref in _paper.tables]
