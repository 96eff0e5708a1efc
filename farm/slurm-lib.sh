# Shared by the Slurm drivers (sourced after lib.sh): submission, and how a
# job array's tasks report a failure in their logs.

# farm_sbatch OPTION...: submits with the driver's options, then the user's
# (after --, so theirs win). Prints the job id alone (--parsable prints ID or
# ID;CLUSTER); returns sbatch's status, with --wait the job's.
farm_sbatch() {
    farm_st=0
    farm_id=$(eval "sbatch --parsable \"\$@\" $FARM_EXTRA") || farm_st=$?
    printf '%s\n' "${farm_id%%;*}"
    return "$farm_st"
}

# farm_task CMD: the body of an array task running CMD; a failure ends the
# task's log with the line farm_failed looks for.
farm_task() {
    printf '%s\n' "$1; s=\$?"
    printf '%s\n' "[ \$s -eq 0 ] || echo \"farm: task \$SLURM_ARRAY_TASK_ID failed: exit \$s\" >&2"
    printf '%s\n' "exit \$s"
}

# farm_failed LOG LAST: finds the first of tasks 0..LAST whose log (LOG with
# %a for the task number) says it failed, prints that log to stderr and sets
# farm_failed_status to its exit status (1 when no log says so: a task was
# then cancelled, timed out or lost with its node).
farm_failed() {
    farm_failed_status=1
    farm_i=0
    while [ "$farm_i" -le "$2" ]; do
        farm_log=$(printf '%s\n' "$1" | sed "s/%a/$farm_i/")
        farm_st=$(sed -n "s/^farm: task $farm_i failed: exit \([0-9]*\)$/\1/p" "$farm_log" 2>/dev/null)
        if [ -n "$farm_st" ]; then
            farm_note "task $farm_i of the job array failed (exit $farm_st); its log $farm_log:"
            sed "s/^/  task $farm_i: /" "$farm_log" >&2
            farm_failed_status=$farm_st
            return 0
        fi
        farm_i=$((farm_i + 1))
    done
    farm_note "no task's log says it failed: one was cancelled, timed out or lost (logs: $1)"
}
