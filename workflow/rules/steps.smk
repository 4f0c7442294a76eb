# Generated rules: one per compute step of each paper's step list
# (src/netrepro/papers/<slug>/steps.yaml, read by netrepro.stepspec), a `<rule>_shard` rule per
# sharded step, and the paper's result tables (PAPER_TABLES). Every paper of the registry gets its
# rules (the figures and the report pick the enabled ones); PAPER_TABLES lists the enabled papers.


# rule name -> its step function (module:function), for the shell command of each generated rule
STEP_FUNCS = {}


def step_func(namespace, defining):
    """The step function of the rule whose ``shell:`` expression is being evaluated.

    Snakemake evaluates a rule's ``shell:`` expression twice: once when the rule is defined (the
    text its code rerun trigger compares, here ``defining``'s) and again when a job runs, inside the
    rule's run function, after this loop has moved on (``_spec`` and ``_step_rule`` are then
    another rule's, so the expression may not touch ``_spec``'s attributes). The run
    function's locals carry the job's ``rule`` name (and Snakemake's run-function marker), so the
    job looks its own function up: the command is ``step(func)`` with the function spelled out, as
    the hand-written rules had it, and a changed function still reruns the rule.
    """
    name = namespace["rule"] if namespace.get(RULEFUNC_CONTEXT_MARKER) else defining
    return STEP_FUNCS[name]


def step_list(slug):
    """The paper's step list, validated before any job runs, or a clear error."""
    try:
        return load_step_specs(slug, root=Path("."))
    except NetreproError as exc:
        raise WorkflowError(str(exc)) from None


def step_output(slug, ref):
    """``<step>[.<output>]`` of paper ``slug`` as the output of the rule that writes it."""
    name, _, output = ref.partition(".")
    return getattr(getattr(rules, f"{slug}_{name}").output, output or "table")


def step_inputs(paper, spec):
    """Named inputs of a step: the step's code, then its declared inputs, then its shard files."""
    named = {"code": code(spec.func)}
    for name, ref in spec.inputs.items():
        if isinstance(ref, str):
            named[name] = ref if "/" in ref else step_output(paper.slug, ref)
        elif "shards" in ref:
            named[name] = getattr(rules, f"{paper.slug}_{ref['shards']}").input.shards
        elif "each" in ref:
            source = paper.step(ref["each"])
            for kind, path in source.outputs.items():
                for value in paper.wildcards[source.over]:
                    named[f"{kind}_{value}"] = expand(path, **{source.over: value})[0]
        else:
            source = paper.step(ref["step"])
            named[name] = expand(source.outputs[ref["output"]], **{source.over: ref["value"]})[0]
    if spec.shard:
        named["shards"] = expand(list(spec.shard.outputs.values())[0], shard=shards(spec.rule))
    return named


def wrapped(cfg, wrap, extra):
    """The params' configuration: the picked keys (nested under ``wrap`` if set) and ``extra``."""
    return {wrap: cfg, **extra} if wrap else {**cfg, **extra}


def shard_params(section, spec):
    """Params of one shard job: the keys the shard reads, its index and the shard count."""

    def cfg(wildcards):
        extra = {"shard": int(wildcards.shard), "n_shards": len(shards(spec.rule))}
        return as_json(wrapped(compose_config(section, spec.shard.config), spec.shard.wrap, extra))

    return cfg


def over_params(section, spec):
    """Params of a step run per wildcard value: that value, and only its entry of ``narrow``."""

    def cfg(wildcards):
        value = wildcards[spec.over]
        picked = compose_config(section, spec.config)
        if spec.narrow:
            picked[spec.narrow] = pick(section.get(spec.narrow, {}), value)
        return as_json(wrapped(picked, spec.wrap, {spec.over: value}))

    return cfg


for _slug in paper_slugs():
    _paper = step_list(_slug)
    _section = config.get(_slug, {})
    for _spec in _paper.steps:
        STEP_FUNCS[_spec.rule] = _spec.func
        if _spec.shard:
            STEP_FUNCS[_spec.shard_rule] = _spec.shard.func
            _step_rule = _spec.shard_rule

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
                    cfg=shard_params(_section, _spec),
                    rule=_spec.shard_rule,
                    io=io_json,
                shell:
                    step(step_func(locals(), _step_rule))

        _step_rule = _spec.rule

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
                cfg=(
                    over_params(_section, _spec)
                    if _spec.over
                    else as_json(compose_config(_section, _spec.config))
                ),
                rule=_spec.rule,
                io=io_json,
            shell:
                step(step_func(locals(), _step_rule))

    if enabled(_slug):
        PAPER_TABLES[_slug] = [step_output(_slug, ref) for ref in _paper.tables]
