# Stage 7: a feeder to build: pin stations, part pitch, belt width,
# throughput and the drawing (JSON, DXF, SVG, PNG) of each planned part.


rule layout:
    input:
        plan=rules.plan.output.plan,
    output:
        layout=f"{RESULTS}/layout_{{name}}.json",
        dxf=f"{RESULTS}/layout_{{name}}.dxf",
        svg=f"{RESULTS}/layout_{{name}}.svg",
        png=report(f"{RESULTS}/layout_{{name}}.png", caption="report/layout.rst",
                   category="Feeder layout"),
    params:
        settings=config["layout"],
    log:
        f"{LOGS}/layout/{{name}}.log",
    benchmark:
        f"{LOGS}/benchmark/layout/{{name}}.tsv"
    conda:
        "envs/pinfeed.yaml"
    script:
        "scripts/layout.py"
