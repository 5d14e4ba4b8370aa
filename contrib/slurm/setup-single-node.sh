#!/bin/bash
# setup-single-node.sh — this machine as a Slurm cluster of one node, for
# evflow's job arrays (docs/scale.md). Debian 12 (slurm-wlm 22.05), as root:
#
#   contrib/slurm/setup-single-node.sh           install, configure, start,
#                                                wait until the node is idle
#   contrib/slurm/setup-single-node.sh --stop    stop slurmd, slurmctld, munged
#   contrib/slurm/setup-single-node.sh --force   also replace a slurm.conf
#                                                this script did not write
#
# It installs slurm-wlm and munge with apt (if missing), creates the munge
# key and the daemons' folders with their owners, writes /etc/slurm/slurm.conf
# from slurm.conf beside it with this machine's host name and its node line
# from `slurmd -C` (without UpTime=), and starts munged (as user munge),
# slurmctld and slurmd: by hand where systemd does not run (a container; the
# path checked in docs/scale.md), with systemctl where it does (not tried).
# Run again, it changes only what differs: daemons already running stay up
# unless slurm.conf changed.
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
template=$here/slurm.conf
conf=/etc/slurm/slurm.conf
marker="# Written by evflow's contrib/slurm/setup-single-node.sh from contrib/slurm/slurm.conf."

say() { echo "setup-single-node: $*"; }
die() {
    echo "setup-single-node: error: $*" >&2
    exit 1
}

force=false
action=start
for arg in "$@"; do
    case $arg in
    --stop) action=stop ;;
    --force) force=true ;;
    -h | --help)
        awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "${BASH_SOURCE[0]}"
        exit 0
        ;;
    *) die "unknown argument '$arg' (--stop, --force, --help)" ;;
    esac
done

[[ $(id -u) -eq 0 ]] || die "run as root: it installs packages, writes /etc/slurm and starts daemons"

systemd=false
[[ -d /run/systemd/system ]] && systemd=true

# The pid in a daemon's pid file, if that process is running under that name.
running_pid() { # NAME PIDFILE
    local pid
    [[ -r $2 ]] || return 1
    pid=$(<"$2")
    [[ $pid =~ ^[0-9]+$ ]] || return 1
    [[ -r /proc/$pid/comm && $(</proc/"$pid"/comm) == "$1" ]] || return 1
    echo "$pid"
}

# Stop a daemon started by hand: TERM to the pid in its pid file, then wait.
stop_by_pidfile() { # NAME PIDFILE
    local pid i
    if pid=$(running_pid "$1" "$2"); then
        kill "$pid"
        for ((i = 0; i < 30; i++)); do
            [[ -d /proc/$pid ]] || break
            sleep 1
        done
        [[ -d /proc/$pid ]] && die "$1 (pid $pid) did not stop within 30 s"
        # slurmctld, running as slurm, cannot remove its own pid file in
        # /run; left there, it fails `apt-get remove slurmctld`.
        rm -f "$2"
        say "stopped $1 (pid $pid)"
    else
        say "$1 is not running (no live pid in $2)"
    fi
}

stop_all() {
    if $systemd; then
        systemctl stop slurmd slurmctld munge
        say "stopped slurmd, slurmctld and munge (systemctl)"
    else
        stop_by_pidfile slurmd /run/slurmd.pid
        stop_by_pidfile slurmctld /run/slurmctld.pid
        stop_by_pidfile munged /run/munge/munged.pid
    fi
}

if [[ $action == stop ]]; then
    stop_all
    exit 0
fi

[[ -r $template ]] || die "no $template: run the script from its folder in the evflow repository"
# shellcheck source=/dev/null
[[ -r /etc/os-release ]] && . /etc/os-release
if [[ ${ID:-} != debian || ${VERSION_ID:-} != 12 ]]; then
    say "warning: written for Debian 12, this is ${PRETTY_NAME:-an unknown system}; going on"
fi

# 1. Packages.
missing=()
for pkg in slurm-wlm munge; do
    dpkg-query -W -f='${Status}\n' "$pkg" 2>/dev/null | grep -qx 'install ok installed' || missing+=("$pkg")
done
if ((${#missing[@]})); then
    say "installing ${missing[*]} with apt"
    apt-get update -q || die "apt-get update failed"
    DEBIAN_FRONTEND=noninteractive apt-get install -y -q "${missing[@]}" ||
        die "apt-get install ${missing[*]} failed"
else
    say "slurm-wlm and munge are installed"
fi
for cmd in munged mungekey slurmctld slurmd sinfo scontrol; do
    command -v "$cmd" >/dev/null || die "$cmd not found after installing slurm-wlm and munge"
done
id munge >/dev/null 2>&1 || die "no user munge (the munge package creates it)"
id slurm >/dev/null 2>&1 || die "no user slurm (the slurm-wlm packages create it)"

# 2. munge: the key and the folders, owned by munge.
install -d -o munge -g munge -m 0700 /etc/munge /var/log/munge
install -d -o munge -g munge -m 0711 /var/lib/munge
install -d -o munge -g munge -m 0755 /run/munge
if [[ ! -s /etc/munge/munge.key ]]; then
    runuser -u munge -- mungekey --create --keyfile=/etc/munge/munge.key ||
        die "mungekey could not create /etc/munge/munge.key"
    say "created /etc/munge/munge.key"
fi
chown munge:munge /etc/munge/munge.key
chmod 0400 /etc/munge/munge.key

# 3. Slurm's folders, owned by slurm: /var/log/slurm holds the daemons'
# logs and the job record (JobCompLoc=/var/log/slurm/jobcomp.log), both
# written by slurmctld as slurm.
install -d -o slurm -g slurm -m 0755 /var/spool/slurmctld /var/spool/slurmd /var/log/slurm
install -d -m 0755 /etc/slurm

# 4. slurm.conf: this machine's host name and node line.
host=$(hostname -s)
[[ -n $host ]] || die "hostname -s printed nothing"
getent hosts "$host" >/dev/null || die "host name '$host' does not resolve (add it to /etc/hosts): slurmd reaches slurmctld through it"
node_line=$(slurmd -C | grep '^NodeName=' | sed -e 's/ *UpTime=[^ ]*//') ||
    die "slurmd -C printed no NodeName= line"
node=${node_line#NodeName=}
node=${node%% *}
[[ $node == "$host" ]] || die "slurmd -C names the node '$node', hostname -s says '$host'"
node_line="$node_line State=UNKNOWN"

new=$(mktemp)
trap 'rm -f "$new"' EXIT
{
    echo "$marker"
    awk -v host="$host" -v node="$node" -v line="$node_line" '
        /^SlurmctldHost=/ { print "SlurmctldHost=" host; next }
        /^NodeName=/      { print line; next }
        /^PartitionName=/ { sub(/ Nodes=[^ ]*/, " Nodes=" node) }
        { print }
    ' "$template"
} >"$new"

conf_changed=true
if [[ -e $conf ]] && cmp -s "$new" "$conf"; then
    conf_changed=false
    say "$conf is up to date"
else
    if [[ -e $conf ]] && ! grep -qxF "$marker" "$conf"; then
        $force || die "$conf exists and was not written by this script; move it away, or run with --force (it is kept as $conf.orig)"
        cp -a "$conf" "$conf.orig"
        say "kept the former $conf as $conf.orig"
    fi
    install -m 0644 "$new" "$conf"
    say "wrote $conf for node $node: $node_line"
fi

# 5. Start munged, slurmctld, slurmd.
wait_for() { # SECONDS COMMAND...: true once COMMAND succeeds
    local secs=$1 i
    shift
    for ((i = 0; i < secs; i++)); do
        "$@" >/dev/null 2>&1 && return 0
        sleep 1
    done
    return 1
}
munge_works() { munge -n | unmunge; }
slurmctld_up() { scontrol ping | grep -q 'is UP'; }

if $systemd; then
    systemctl enable --now munge
    systemctl enable slurmctld slurmd
    if $conf_changed; then
        systemctl restart slurmctld slurmd
    else
        systemctl start slurmctld slurmd
    fi
    wait_for 30 munge_works || die "munge does not answer: systemctl status munge; /var/log/munge/munged.log"
    wait_for 30 slurmctld_up || die "slurmctld does not answer: systemctl status slurmctld; /var/log/slurm/slurmctld.log"
else
    if munge_works >/dev/null 2>&1; then
        say "munged is running"
    else
        # As user munge: munged refuses to run as root ("Logfile is insecure").
        runuser -u munge -- munged || die "munged did not start; see /var/log/munge/munged.log"
        wait_for 10 munge_works || die "munged does not answer; see /var/log/munge/munged.log"
        say "started munged as user munge (pid $(cat /run/munge/munged.pid))"
    fi
    if $conf_changed; then
        # A changed node line needs the daemons restarted, not reconfigured.
        if running_pid slurmd /run/slurmd.pid >/dev/null; then stop_by_pidfile slurmd /run/slurmd.pid; fi
        if running_pid slurmctld /run/slurmctld.pid >/dev/null; then stop_by_pidfile slurmctld /run/slurmctld.pid; fi
    fi
    if running_pid slurmctld /run/slurmctld.pid >/dev/null; then
        say "slurmctld is running"
    else
        slurmctld || die "slurmctld did not start; see /var/log/slurm/slurmctld.log"
        wait_for 30 slurmctld_up || {
            tail -n 20 /var/log/slurm/slurmctld.log >&2 || true
            die "slurmctld does not answer (scontrol ping); its log's end is above"
        }
        say "started slurmctld (pid $(cat /run/slurmctld.pid))"
    fi
    if running_pid slurmd /run/slurmd.pid >/dev/null; then
        say "slurmd is running"
    else
        slurmd || die "slurmd did not start; see /var/log/slurm/slurmd.log"
        wait_for 10 running_pid slurmd /run/slurmd.pid ||
            die "slurmd wrote no /run/slurmd.pid; see /var/log/slurm/slurmd.log"
        say "started slurmd (pid $(cat /run/slurmd.pid))"
    fi
fi

# 6. Wait until the node is idle.
node_idle() { [[ $(sinfo -h -n "$node" -o %t) == idle ]]; }
if ! wait_for 60 node_idle; then
    sinfo -N -l >&2 || true
    sinfo -R >&2 || true
    tail -n 20 /var/log/slurm/slurmd.log >&2 || true
    die "node $node is not idle after 60 s (sinfo and slurmd's log above)"
fi
sinfo --version
sinfo
say "ready: submit from a folder with graphs/ (contrib/slurm/README.md); ended jobs: /var/log/slurm/jobcomp.log, scontrol show job ID"
