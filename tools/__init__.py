"""The workbook's experiments and maintenance scripts; each runs as `python tools/NAME.py --help`
(→ names the table in notebooks/data/ that a tool writes and a notebook reads).

    common                 shared helpers: ROOT, DATA_DIR, update_json, val_pairs, score_outputs, recorded_command,
                           current_commit
    adain_variants         A stage 1 design checks, recipes and strength on val pairs → 02_adain_variants.json
    dsdn_ablation          A Table 2 (DSDN's streams) and the correction strength → 05_dsdn_ablation.json
    mcm_ldm_ablations      B Table 2 ablations, the λ sweep, and λ, steps and seed chosen on val → 04_ablations.json
    contrastive_analysis   C Fig. 2, Table 1, Fig. 10–11, Fig. 3 from short runs → 03_contrastive_findings.json
    contrastive_findings   C's recipe variants, seeds and strengths on val pairs → 03_contrastive_recipes.json
    clusterstyle_findings  D Fig. 5 (pose sets) and Table 3 (ablations) → 06_clusterstyle_findings.json
    real_bench             every method on real pairs (Xia grid styles, real contents), judged twice → 07_real_bench.json
    real_val               each course knob on held-out Xia train takes (real val pairs), chosen with the built-in val H → 07_real_val.json
    fit_styles             the generator's body and style means fitted to the Xia train split → mslib/data/fitted_styles.json
    fit_joint_moments      the generator's per-joint layer (offset, gain, variation per style × content) → mslib/data/fitted_joint_moments.json
    evaluator_augment      training augmentations of the style evaluator, scored on real train takes → 00_evaluator_augment.json
    realism_gap            which feature groups, matched per style × content, close the real → built-in gap → 00_realism_gap.json
    build_notebooks        notebooks/src/*.py → executed notebooks/*.ipynb (the outputs nbval checks)
    release                the workbook as an nbgrader course (make release) and autograding (make grade)
    train_all              every packaged checkpoint retrained with its course seed, in dependency order
    update_docs            the measured tables in README.md (built-in and real benchmarks) and notebooks/INSTRUCTORS.md

Experiments live here, not in `mslib`: the library holds the papers and the course recipes, a tool
holds the research recipe that produced a stored table. Design choices are scored on the validation
splits (`common.val_pairs`), never on the benchmark's test pairs.
"""
