# The long part of the work-precision scene (results/work_precision_full, `make reproduce-all`):
# the same figures as scripts/work_precision.gp, from this folder's summary.csv.
load scripts."/work_precision.gp"
