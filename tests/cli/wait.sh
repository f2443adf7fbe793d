# Waiting helpers of the shell tests that signal a running godrays (source it).
# wait_gone PID SECONDS: 0 when PID ended within SECONDS
wait_gone() {
    n=0
    while kill -0 "$1" 2>/dev/null; do
        n=$((n + 1))
        [ "$n" -gt $(($2 * 20)) ] && return 1
        sleep 0.05
    done
    return 0
}
# wait_for TEXT FILE SECONDS: 0 when FILE contains TEXT within SECONDS
wait_for() {
    n=0
    until grep -q "$1" "$2" 2>/dev/null; do
        n=$((n + 1))
        [ "$n" -gt $(($3 * 20)) ] && return 1
        sleep 0.05
    done
}
