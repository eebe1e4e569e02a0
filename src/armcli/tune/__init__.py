"""`armcli tune`: PD gains from the model, refined over rollouts, optionally on Dask.

Stages, one module each: `problem` (what is evaluated: arm, cases, perturbed models),
`gains` (the candidate vector's layout), `model_gains` (the instant model-based start),
`spec_start` (that start for a spec without gains), `objective` (metrics and the
documented cost), `evaluate` (score a chunk of candidates), `engine` (run chunks locally
or on Dask), `search` (seeded Optuna in fixed-size batches), `job` (inputs -> problem),
`session` (one tuning end to end), `report`, `plot` and `write`.
"""
