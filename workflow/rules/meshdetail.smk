# Hybrid mesh animation (skinned 18-joint skeleton + learned time-varying detail,
# SGPLVM + GPDM). Resources: peak memory measured on samba (9,971 vertices,
# 175 frames: rig 0.85 GB, main/resolution 0.75 GB) with headroom; runtime in
# minutes, from the samba run on a heavily loaded 2-core machine x 2-3. Data: the synthetic skirt character (mesh_dir: null)
# or a folder of OBJ / OBJ.gz frames (config/samba.yaml), plus further real sequences
# (meshdetail.sequences, e.g. crane in config/paper.yaml). Every job runs on one
# sequence ({mdseq}: results/meshdetail/<sequence>/...); meshdetail_compare puts the
# sequences side by side. Every job gets only the config keys it uses, so a changed
# value reruns exactly the affected jobs. Input functions: common.smk ("meshdetail input
# functions"); config checks: animsynth.meshdetail.settings.check (called from common.smk).
MD = config["meshdetail"]
MD_MODEL_KEYS = (
    "level", "latent_dim", "iterations", "dynamics_weight", "ridge_alphas", "joint_param", "detail", "decimation",
    "rbf_neighbors", "cv_folds", "cv_rig",
)
MD_MODEL_CFG = {k: MD[k] for k in MD_MODEL_KEYS}
MD_NAMES = list(MD_SEQS)  # sequences of this run (MD_SEQS: common.smk; unreadable ones already left out)


wildcard_constraints:
    mdseq="|".join(map(re.escape, MD_NAMES)),


MD_DATA = dict(
    seq=R("meshdetail/{mdseq}/data/sequence.npz"),
    edits=R("meshdetail/{mdseq}/data/edits.npz"),
    pose=R("meshdetail/{mdseq}/data/pose.npz"),
)
MD_PER_SEQUENCE = [
    "rig_fit.csv", "joints.csv", "skinning.csv", "fig5a.csv", "fig5b.csv", "fig5c.csv", "representations.csv",
    "generalisation.csv", "fig5b_timing.csv", "dembones.csv", "dembones_timing.csv", "fig5a.png", "fig5b.png", "fig5c.png", "frames.png",
    "error_map.png", "verdicts.csv",
]
MESHDETAIL_TARGETS = [R(f"meshdetail/{n}/{f}") for n in MD_NAMES for f in MD_PER_SEQUENCE] + [
    R("meshdetail/sequences.csv"),
    R("meshdetail/verdicts.csv"),
]


rule meshdetail_character:
    output:
        main=directory(R("meshdetail/character/main")),
        edits=[directory(R(f"meshdetail/character/edit_{e}")) for e in MD["character"]["edits"]],
        truth=R("meshdetail/character/truth.npz"),
    params:
        cfg=MD["character"],
        seed=seed_for("meshdetail", MD["seed"], "character"),
    threads: 1
    resources:
        mem_mb=1500,
        runtime=20,
    log:
        L("meshdetail/character.log"),
    benchmark:
        B("meshdetail/character.tsv")
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/meshdetail_character.py"


rule meshdetail_load:
    input:
        main=md_frames,
        truth=md_truth,
        edits=md_edit_dirs,
        checked=md_checked,
    output:
        seq=MD_DATA["seq"],
        edits=MD_DATA["edits"],
    params:
        fps=md_fps,
        max_frames=MD["max_frames"],
    threads: 1
    resources:
        mem_mb=1000,
        runtime=10,
    log:
        L("meshdetail/{mdseq}/load.log"),
    benchmark:
        B("meshdetail/load/{mdseq}.tsv")
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/meshdetail_load.py"


rule meshdetail_rig:
    input:
        seq=MD_DATA["seq"],
        truth=md_truth,
    output:
        pose=MD_DATA["pose"],
        table=report(
            R("meshdetail/{mdseq}/rig_fit.csv"),
            caption="../report/meshdetail_rig_fit.rst",
            category="Meshdetail",
            subcategory="Skeleton fit",
        ),
        joints=report(
            R("meshdetail/{mdseq}/joints.csv"),
            caption="../report/meshdetail_joints.rst",
            category="Meshdetail",
            subcategory="Skeleton fit",
        ),
        skinning=report(
            R("meshdetail/{mdseq}/skinning.csv"),
            caption="../report/meshdetail_skinning.rst",
            category="Meshdetail",
            subcategory="Skeleton fit",
        ),
        table_md=R("meshdetail/{mdseq}/rig_fit.md"),
        joints_md=R("meshdetail/{mdseq}/joints.md"),
        skinning_md=R("meshdetail/{mdseq}/skinning.md"),
    params:
        rig=md_rig,
        train_fraction=MD["train_fraction"],
    threads: 1
    resources:
        mem_mb=2000,
        runtime=20,
    log:
        L("meshdetail/{mdseq}/rig.log"),
    benchmark:
        B("meshdetail/rig/{mdseq}.tsv")
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/meshdetail_rig.py"


rule meshdetail_main:
    input:
        **MD_DATA,
        truth=md_truth,
    output:
        fig5a=report(
            R("meshdetail/{mdseq}/fig5a.csv"),
            caption="../report/meshdetail_fig5a.rst",
            category="Meshdetail",
            subcategory="Fig. 5",
        ),
        fig5c=report(
            R("meshdetail/{mdseq}/fig5c.csv"),
            caption="../report/meshdetail_fig5c.rst",
            category="Meshdetail",
            subcategory="Fig. 5",
        ),
        gen=report(
            R("meshdetail/{mdseq}/generalisation.csv"),
            caption="../report/meshdetail_generalisation.rst",
            category="Meshdetail",
            subcategory="Generalisation",
        ),
        fig5a_md=R("meshdetail/{mdseq}/fig5a.md"),
        fig5c_md=R("meshdetail/{mdseq}/fig5c.md"),
        gen_md=R("meshdetail/{mdseq}/generalisation.md"),
        preds=R("meshdetail/{mdseq}/data/predictions.npz"),
    params:
        cfg=MD_MODEL_CFG,
        rig=md_rig,
        train_fraction=MD["train_fraction"],
        render_frames=md_render_frames,
    threads: 1
    resources:
        mem_mb=2000,
        runtime=30,
    log:
        L("meshdetail/{mdseq}/main.log"),
    benchmark:
        B("meshdetail/main/{mdseq}.tsv")
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/meshdetail_main.py"


rule meshdetail_resolution:
    input:
        **MD_DATA,
    output:
        fig5b=report(
            R("meshdetail/{mdseq}/fig5b.csv"),
            caption="../report/meshdetail_fig5b.rst",
            category="Meshdetail",
            subcategory="Fig. 5",
        ),
        timing=report(
            R("meshdetail/{mdseq}/fig5b_timing.csv"),
            caption="../report/meshdetail_timing.rst",
            category="Meshdetail",
            subcategory="Performance",
        ),
        fig5b_md=R("meshdetail/{mdseq}/fig5b.md"),
        timing_md=R("meshdetail/{mdseq}/fig5b_timing.md"),
    params:
        cfg=dict(MD_MODEL_CFG, levels=MD["levels"]),
        train_fraction=MD["train_fraction"],
    threads: 1
    resources:
        mem_mb=2000,
        runtime=20,
    log:
        L("meshdetail/{mdseq}/resolution.log"),
    benchmark:
        B("meshdetail/resolution/{mdseq}.tsv")
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/meshdetail_resolution.py"


rule meshdetail_representations:
    input:
        **MD_DATA,
    output:
        table=report(
            R("meshdetail/{mdseq}/representations.csv"),
            caption="../report/meshdetail_representations.rst",
            category="Meshdetail",
            subcategory="Representations",
        ),
        table_md=R("meshdetail/{mdseq}/representations.md"),
    params:
        cfg=MD_MODEL_CFG,
        train_fraction=MD["train_fraction"],
    threads: 1
    resources:
        mem_mb=1500,
        runtime=10,
    log:
        L("meshdetail/{mdseq}/representations.log"),
    benchmark:
        B("meshdetail/representations/{mdseq}.tsv")
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/meshdetail_representations.py"


rule meshdetail_figures:
    input:
        fig5a=R("meshdetail/{mdseq}/fig5a.csv"),
        fig5b=R("meshdetail/{mdseq}/fig5b.csv"),
        fig5c=R("meshdetail/{mdseq}/fig5c.csv"),
        preds=R("meshdetail/{mdseq}/data/predictions.npz"),
        dembones=R("meshdetail/{mdseq}/data/dembones_predictions.npz"),
        seq=MD_DATA["seq"],
    output:
        fig5a=report(
            R("meshdetail/{mdseq}/fig5a.png"),
            caption="../report/meshdetail_fig5a.rst",
            category="Meshdetail",
            subcategory="Fig. 5",
        ),
        fig5b=report(
            R("meshdetail/{mdseq}/fig5b.png"),
            caption="../report/meshdetail_fig5b.rst",
            category="Meshdetail",
            subcategory="Fig. 5",
        ),
        fig5c=report(
            R("meshdetail/{mdseq}/fig5c.png"),
            caption="../report/meshdetail_fig5c.rst",
            category="Meshdetail",
            subcategory="Fig. 5",
        ),
        frames=report(
            R("meshdetail/{mdseq}/frames.png"),
            caption="../report/meshdetail_frames.rst",
            category="Meshdetail",
            subcategory="Rendered frames",
        ),
        error_map=report(
            R("meshdetail/{mdseq}/error_map.png"),
            caption="../report/meshdetail_error_map.rst",
            category="Meshdetail",
            subcategory="Rendered frames",
        ),
    params:
        name=md_name,
    threads: 1
    resources:
        mem_mb=1000,
        runtime=5,
    log:
        L("meshdetail/{mdseq}/figures.log"),
    benchmark:
        B("meshdetail/figures/{mdseq}.tsv")
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/meshdetail_figures.py"


rule meshdetail_verdicts:
    input:
        fig5a=R("meshdetail/{mdseq}/fig5a.csv"),
        fig5b=R("meshdetail/{mdseq}/fig5b.csv"),
        fig5c=R("meshdetail/{mdseq}/fig5c.csv"),
        gen=R("meshdetail/{mdseq}/generalisation.csv"),
    output:
        csv=report(
            R("meshdetail/{mdseq}/verdicts.csv"),
            caption="../report/meshdetail_verdicts.rst",
            category="Meshdetail",
            subcategory="Verdicts",
        ),
        md=R("meshdetail/{mdseq}/verdicts.md"),
    params:
        source=md_data_source,
        cv_rig=MD["cv_rig"],
    threads: 1
    resources:
        mem_mb=500,
        runtime=5,
    log:
        L("meshdetail/{mdseq}/verdicts.log"),
    benchmark:
        B("meshdetail/verdicts/{mdseq}.tsv")
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/meshdetail_verdicts.py"


rule meshdetail_dembones:
    input:
        seq=MD_DATA["seq"],
    output:
        table=report(
            R("meshdetail/{mdseq}/dembones.csv"),
            caption="../report/meshdetail_dembones.rst",
            category="Meshdetail",
            subcategory="LBS floor (Dem Bones)",
        ),
        timing=report(
            R("meshdetail/{mdseq}/dembones_timing.csv"),
            caption="../report/meshdetail_dembones.rst",
            category="Meshdetail",
            subcategory="Performance",
        ),
        table_md=R("meshdetail/{mdseq}/dembones.md"),
        timing_md=R("meshdetail/{mdseq}/dembones_timing.md"),
        preds=R("meshdetail/{mdseq}/data/dembones_predictions.npz"),
    params:
        cfg=MD["dembones"],
        cv_folds=MD["cv_folds"],
        render_frames=md_render_frames,
    # samba (9,971 vertices, 175 frames), bones [18, 40]: SSDR fit 7 + 11 s, held-out solve 3.5 + 7.5 s CPU per fold
    threads: 1
    resources:
        mem_mb=1500,
        runtime=20,
    log:
        L("meshdetail/{mdseq}/dembones.log"),
    benchmark:
        B("meshdetail/dembones/{mdseq}.tsv")
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/meshdetail_dembones.py"


rule meshdetail_compare:
    input:
        gen=expand(R("meshdetail/{mdseq}/generalisation.csv"), mdseq=MD_NAMES),
        dembones=expand(R("meshdetail/{mdseq}/dembones.csv"), mdseq=MD_NAMES),
        verdicts=expand(R("meshdetail/{mdseq}/verdicts.csv"), mdseq=MD_NAMES),
    output:
        table=report(
            R("meshdetail/sequences.csv"),
            caption="../report/meshdetail_sequences.rst",
            category="Meshdetail",
            subcategory="Sequences side by side",
        ),
        verdicts=report(
            R("meshdetail/verdicts.csv"),
            caption="../report/meshdetail_verdicts.rst",
            category="Meshdetail",
            subcategory="Verdicts",
        ),
        table_md=R("meshdetail/sequences.md"),
        verdicts_md=R("meshdetail/verdicts.md"),
    params:
        names=MD_NAMES,
    threads: 1
    resources:
        mem_mb=500,
        runtime=5,
    log:
        L("meshdetail/compare.log"),
    benchmark:
        B("meshdetail/compare.tsv")
    conda:
        "../envs/animsynth.yaml"
    script:
        "../scripts/meshdetail_compare.py"


# Tables for results/summary.md and verdict files (collected by report.smk).
MESHDETAIL_SUMMARY = [
    {
        "title": "Hybrid mesh animation: sequences side by side (held-out frames, blocked CV)",
        "csv": R("meshdetail/sequences.csv"),
        "note": "Mean vertex error (mm) over the folds of the blocked cross-validation and the fold SD, per sequence: "
        "our skin (LBS of the fitted 18-joint skeleton), the Dem Bones LBS floor per bone count (SSDR weights from "
        "the training blocks, transforms solved on the held-out meshes), the hybrid, the hybrid without dynamics, "
        "plain GP regression, CV ridge.",
    },
]
for _n in MD_NAMES:
    _src = md_source(_n)
    MESHDETAIL_SUMMARY += [
        {
            "title": f"Hybrid mesh animation [{_n}]: skeleton fit",
            "csv": R(f"meshdetail/{_n}/rig_fit.csv"),
            "note": f"Data: {_src}. LBS residual of the fitted 18-joint skeleton (mm), overall and per bone, "
            "training and held-out frames.",
        },
        {
            "title": f"Hybrid mesh animation [{_n}]: skinning methods",
            "csv": R(f"meshdetail/{_n}/skinning.csv"),
            "note": f"Data: {_src}. Bone heat, bone heat refitted on the training frames, distance falloff (mm).",
        },
        {
            "title": f"Hybrid mesh animation [{_n}]: joint centres inside the first-frame mesh",
            "csv": R(f"meshdetail/{_n}/joints.csv"),
            "note": f"Data: {_src}. Winding number 1 = inside the closed mesh.",
        },
        {
            "title": f"Hybrid mesh animation [{_n}] Fig. 5b: error and size vs control-mesh resolution",
            "csv": R(f"meshdetail/{_n}/fig5b.csv"),
            "note": f"Data: {_src}. Mean vertex error (mm) on training / held-out frames; replayed edge "
            "collapses (paper) and a farthest-point vertex subset.",
        },
        {
            "title": f"Hybrid mesh animation [{_n}]: generalisation (Fig. 5c summary, held-out frames, edited motions)",
            "csv": R(f"meshdetail/{_n}/generalisation.csv"),
            "note": f"Data: {_src}. Mean vertex error (mm) over blocked-CV folds and its fold SD: LBS only, "
            "hybrid (SGPLVM+GPDM), plain GP regression, CV-tuned ridge, hybrid without dynamics.",
        },
        {
            "title": f"Hybrid mesh animation [{_n}]: LBS floor with Dem Bones, per fold",
            "csv": R(f"meshdetail/{_n}/dembones.csv"),
            "note": f"Data: {_src}. SSDR weights fitted on each fold's training blocks; held-out: weights fixed, "
            "rigid bone transforms solved from the held-out meshes (affine beside it).",
        },
        {
            "title": f"Hybrid mesh animation [{_n}]: Dem Bones fit and solve time (machine-dependent)",
            "csv": R(f"meshdetail/{_n}/dembones_timing.csv"),
            "note": "CPU and wall seconds per fold and bone count.",
        },
        {
            "title": f"Hybrid mesh animation [{_n}]: representations",
            "csv": R(f"meshdetail/{_n}/representations.csv"),
            "note": f"Data: {_src}. Joint parameterisation x detail encoding (mm).",
        },
        {
            "title": f"Hybrid mesh animation [{_n}]: timing (machine-dependent)",
            "csv": R(f"meshdetail/{_n}/fig5b_timing.csv"),
            "note": "Wall and CPU seconds of training per 100 frames and one-frame reconstruction time per level.",
        },
    ]
MESHDETAIL_VERDICTS = [R("meshdetail/verdicts.csv")]
# Key figures for the summary and the report's home page, with what to see in them.
MESHDETAIL_FIGURES = [
    {
        "png": R(f"meshdetail/{MD_NAMES[0]}/fig5c.png"),
        "caption": f"Per-frame mean vertex error on held-out frames ({MD_NAMES[0]}, blocked cross-validation): "
        "the hybrid below linear blend skinning alone is the paper's claim that the learned detail helps on "
        "frames it never saw; the plain GP and ridge lines are the baselines it must beat.",
    }
] if MD_NAMES else []
