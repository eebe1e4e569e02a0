"""`armcli tune`: PD gains from the model, refined over rollouts, optionally on Dask.

Stages, one module each: `problem` (what is evaluated: arm, cases, perturbed models),
`model_gains` (the instant model-based start), `objective` (metrics and the documented
cost), `engine` (evaluate a batch of candidates locally or on Dask), `search` (seeded
Optuna in fixed-size batches), `job` (inputs -> problem), `report`, `plot` and `write`.
"""
