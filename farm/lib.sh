# Shared by the farm drivers (sourced, POSIX sh): argument parsing, tool
# lookup, quoting and messages. A driver sets FARM_PROG (its name), FARM_KIND
# (rasterize or render) and FARM_ENGINE (parallel or slurm), defines
# farm_usage (prints its --help text), then calls farm_parse "$@".
#
# After farm_parse:
#   FARM_INPUT   SCENE (rasterize) or FILE.oct (render), absolute
#   FARM_OUT     OUT.oct, absolute (rasterize)
#   FARM_COUNT   the number of shards (--shards) or parts (--parts)
#   FARM_JOBS    --jobs J (parallel; empty: parallel's default)
#   FARM_WAIT    1 with --wait (slurm)
#   FARM_TMPDIR  --tmpdir DIR, absolute (rasterize; default: OUT's directory)
#   FARM_PASS    options for every program run, each word quoted for eval
#   FARM_EXTRA   the words after --, for parallel or sbatch, quoted for eval
# Use a quoted list as: eval "set -- $FARM_PASS"

FARM_ROOT=$(cd "$(dirname "$0")/.." && pwd)

farm_usage_error() {
    printf '%s: %s\n' "$FARM_PROG" "$*" >&2
    printf "Try '%s --help'.\n" "$FARM_PROG" >&2
    exit 2
}

farm_die() {
    printf '%s: %s\n' "$FARM_PROG" "$*" >&2
    exit 1
}

farm_note() { printf '%s: %s\n' "$FARM_PROG" "$*" >&2; }

# farm_quote WORD: WORD in single quotes, safe to paste into a shell command.
farm_quote() {
    printf "'%s'" "$(printf '%s' "$1" | sed "s/'/'\\\\''/g")"
}

# farm_count OPTION VALUE: VALUE is a whole number >= 1 (no sign, no spaces).
farm_count() {
    case $2 in
        '' | *[!0-9]* | 0*) farm_usage_error "$1: '$2' is not a whole number >= 1" ;;
    esac
    [ ${#2} -le 9 ] || farm_usage_error "$1: '$2' is too large"
}

# farm_abs PATH: PATH made absolute (its directory must exist).
farm_abs() {
    case $1 in
        /*) printf '%s\n' "$1" ;;
        *) printf '%s/%s\n' "$(pwd)" "$1" ;;
    esac
}

# farm_tool NAME VAR: sets FARM_TOOL to the program NAME: $VAR if set, else
# bin/NAME of this repository, else NAME from PATH. Exit 1 if none runs.
farm_tool() {
    eval "farm_t=\${$2:-}"
    if [ -n "$farm_t" ]; then
        case $farm_t in
            */*) farm_t=$(farm_abs "$farm_t")
                 [ -f "$farm_t" ] && [ -x "$farm_t" ] || farm_die "$2=$farm_t: not an executable file" ;;
            *) command -v "$farm_t" >/dev/null 2>&1 || farm_die "$2=$farm_t: not found in PATH" ;;
        esac
        FARM_TOOL=$farm_t
    elif [ -x "$FARM_ROOT/bin/$1" ]; then
        FARM_TOOL=$FARM_ROOT/bin/$1
    elif command -v "$1" >/dev/null 2>&1; then
        FARM_TOOL=$1   # left bare: other machines find it in their own PATH
    else
        farm_die "$1 not found: build it (make in $FARM_ROOT), put it in PATH or set $2"
    fi
}

# farm_need COMMAND PACKAGE: exit 1 with a hint when COMMAND is missing.
farm_need() {
    command -v "$1" >/dev/null 2>&1 ||
        farm_die "$1 not found: install $2 (Debian: apt-get install $2)"
}

# farm_value OPTION ARGC: an option's value must follow it.
farm_value() {
    [ "$2" -ge 2 ] || farm_usage_error "$1 needs a value"
}

# Render takes every word the driver does not know (render checks them);
# the driver only counts --views and --orbit.
farm_pass_render() {
    case $1 in --views | --orbit) farm_views=$((farm_views + 1)) ;; esac
    FARM_PASS="$FARM_PASS $(farm_quote "$1")"
}

farm_parse() {
    FARM_INPUT='' FARM_OUT='' FARM_COUNT='' FARM_JOBS='' FARM_WAIT=0 FARM_TMPDIR=''
    FARM_PASS='' FARM_EXTRA='' farm_levels='' farm_views=0
    farm_countopt=--parts
    [ "$FARM_KIND" = rasterize ] && farm_countopt=--shards
    # render's FILE.oct comes first: the words after it may be option values
    if [ "$FARM_KIND" = render ] && [ $# -gt 0 ] && [ "$1" = "${1#-}" ]; then
        FARM_INPUT=$1; shift
    fi
    while [ $# -gt 0 ]; do
        case $1 in
            -h | --help) farm_usage; exit 0 ;;
            --) shift; break ;;
            "$farm_countopt") farm_value "$1" $#; farm_count "$1" "$2"; FARM_COUNT=$2; shift 2 ;;
            --shards | --parts) farm_usage_error "unknown option '$1'" ;;   # the other kind's
            --jobs) [ "$FARM_ENGINE" = parallel ] || farm_usage_error "unknown option '$1'"
                farm_value "$1" $#; farm_count "$1" "$2"; FARM_JOBS=$2; shift 2 ;;
            --wait) [ "$FARM_ENGINE" = slurm ] || farm_usage_error "unknown option '$1'"
                FARM_WAIT=1; shift ;;
            --shard | --part | --merge) farm_usage_error "$1 is the driver's to set" ;;
            --tmpdir) [ "$FARM_KIND" = rasterize ] || farm_usage_error "unknown option '$1'"
                farm_value "$1" $#; [ -d "$2" ] || farm_die "--tmpdir $2: not a directory"
                FARM_TMPDIR=$(cd "$2" && pwd); shift 2 ;;
            --levels) [ "$FARM_KIND" = rasterize ] || farm_usage_error "unknown option '$1'"
                farm_value "$1" $#; farm_count "$1" "$2"; farm_levels=$2
                FARM_PASS="$FARM_PASS --levels $2"; shift 2 ;;
            --method | --threads)
                [ "$FARM_KIND" = rasterize ] || { farm_pass_render "$1"; shift; continue; }
                farm_value "$1" $#
                FARM_PASS="$FARM_PASS $(farm_quote "$1") $(farm_quote "$2")"; shift 2 ;;
            *) if [ "$FARM_KIND" = render ]; then
                   farm_pass_render "$1"
               elif [ "$1" = --shell-only ]; then
                   FARM_PASS="$FARM_PASS $1"
               elif [ -z "$FARM_INPUT" ] && [ "$1" = "${1#-}" ]; then
                   FARM_INPUT=$1
               elif [ -z "$FARM_OUT" ] && [ "$1" = "${1#-}" ]; then
                   FARM_OUT=$1
               else
                   case $1 in
                       -*) farm_usage_error "unknown option '$1'" ;;
                       *) farm_usage_error "unexpected argument '$1'" ;;
                   esac
               fi
               shift ;;
        esac
    done
    for farm_w in "$@"; do FARM_EXTRA="$FARM_EXTRA $(farm_quote "$farm_w")"; done

    if [ "$FARM_KIND" = rasterize ]; then
        [ -n "$FARM_OUT" ] || farm_usage_error "needs SCENE and OUT.oct"
        [ -n "$farm_levels" ] || farm_usage_error "needs --levels L"
        case $FARM_OUT in */) farm_usage_error "OUT.oct '$FARM_OUT' names a directory" ;; esac
        farm_outdir=$(dirname "$FARM_OUT")
        [ -d "$farm_outdir" ] || farm_die "$FARM_OUT: no directory $farm_outdir"
        FARM_OUT=$(cd "$farm_outdir" && pwd)/$(basename "$FARM_OUT")
        [ -n "$FARM_TMPDIR" ] || FARM_TMPDIR=$(dirname "$FARM_OUT")
    else
        [ -n "$FARM_INPUT" ] || farm_usage_error "needs FILE.oct"
        [ "$farm_views" -eq 1 ] || farm_usage_error "needs one of --views FILE or --orbit N"
    fi
    [ -n "$FARM_COUNT" ] || farm_usage_error "needs $farm_countopt N"
    # a Slurm render may wait (--dependency) for the job that writes its FILE.oct
    if [ "$FARM_KIND$FARM_ENGINE" != renderslurm ]; then
        [ -f "$FARM_INPUT" ] && [ -r "$FARM_INPUT" ] || farm_die "$FARM_INPUT: no such readable file"
    fi
    FARM_INPUT=$(farm_abs "$FARM_INPUT")
}
