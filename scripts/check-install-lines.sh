#!/usr/bin/env bash
# Checks the README's install lines on a fresh Debian 12 (bookworm) built with debootstrap
# (issue 29, class 10). Needs root, debootstrap and the network (Debian's mirror, rustup's
# download server, crates.io, PyPI); not part of .ci/run for that reason.
#
#   sudo scripts/check-install-lines.sh [STAGE ...]     # default: rust train test ros python
#
# The lines are read from README.md of the checkout's committed HEAD (a bare clone of it is what
# the fresh system clones), so this checks what the README says, not a copy of it:
#   rust    the "Install" block on a minimal system: its apt-get line, rustup, `. ~/.cargo/env`,
#           git clone, cargo build --release
#   train   the README's first command (`cargo run --release -- train`)
#   test    its second (`cargo test --release`: 10 to 30 minutes on two cores)
#   ros     the "Running on robots with ROS" apt-get line, then `scripts/ros-smoke.sh`
#   python  the "From Python" block (its apt-get line, venv, `pip install ./python`, import)
# Each stage prints PASS or FAIL with its wall time; its whole output is in $CHECK_DIR/logs/.
#
# Layers: the minimal system ($BASE, made with `debootstrap --variant=minbase` if absent) is never
# changed; each stage writes into its own overlayfs layer over the one it starts from: rust over
# the base; train over rust; test, ros and python each over train (over rust when train was not
# run), so each starts from a system with only the Rust toolchain and the built checkout, never
# from another's packages. A stage given again starts its layer anew (and the layers over it are
# then stale: give them again too); before a stage over rust, the checkout there is moved to the
# commit checked (as `git pull` would). test, ros and python may run in separate invocations at
# the same time. Everything mounted is unmounted when the script ends, also on failure or Ctrl-C,
# after any process still running inside its chroots is killed.
#
# Environment: CHECK_DIR (default /var/tmp/macdec-install-check), BASE (default $CHECK_DIR/base),
# MIRROR (default http://deb.debian.org/debian), CARGO_BUILD_JOBS (passed on if set).
# Exit status 0 only if every stage run passed.
set -euo pipefail

repo=$(cd "$(dirname "$0")/.." && pwd)
check_dir=${CHECK_DIR:-/var/tmp/macdec-install-check}
base=${BASE:-$check_dir/base}
mirror=${MIRROR:-http://deb.debian.org/debian}
stages=("$@")
[ ${#stages[@]} -gt 0 ] || stages=(rust train test ros python)
for s in "${stages[@]}"; do
    case $s in rust | train | test | ros | python) ;; *) echo "unknown stage: $s" >&2; exit 2 ;; esac
done
[ "$(id -u)" = 0 ] || { echo "check-install-lines: needs root (chroot, mount)" >&2; exit 2; }
grep -qw overlay /proc/filesystems || modprobe overlay 2>/dev/null || {
    echo "check-install-lines: this kernel has no overlayfs" >&2
    exit 2
}
mkdir -p "$check_dir/logs" "$check_dir/layers" "$check_dir/mnt"

mounted=() # merged roots now mounted, in mount order

# Kill every process whose root is inside $1 (only this script's chroots), then unmount it all.
unmount_root() {
    local root=$1 p i
    for i in 1 2 3; do
        for p in /proc/[0-9]*; do
            [ "$(readlink "$p/root" 2>/dev/null)" = "$root" ] && kill -KILL "${p#/proc/}" 2>/dev/null
        done
        sleep 0.5
    done
    umount -R "$root" 2>/dev/null || umount -R -l "$root"
}
cleanup() {
    local i
    for ((i = ${#mounted[@]} - 1; i >= 0; i--)); do unmount_root "${mounted[$i]}" || true; done
    mounted=()
    rm -rf "${src:-}" "${readme:-}"
}
trap cleanup EXIT
trap 'exit 130' INT TERM

if [ ! -x "$base/bin/bash" ]; then
    command -v debootstrap >/dev/null || {
        echo "check-install-lines: debootstrap not found: apt-get install -y debootstrap" >&2
        exit 2
    }
    echo "check-install-lines: building a minimal bookworm in $base (debootstrap)" >&2
    debootstrap --variant=minbase bookworm "$base" "$mirror" >"$check_dir/logs/debootstrap.log" 2>&1 || {
        tail -20 "$check_dir/logs/debootstrap.log" >&2
        exit 1
    }
fi

# The code the fresh system clones: the checkout's committed HEAD (not its work tree).
src=$check_dir/src-$$.git
git clone -q --bare "$repo" "$src"
readme=$(mktemp)
git -C "$src" show HEAD:README.md >"$readme"
commit=$(git -C "$src" rev-parse --short HEAD)

# Lines of the N-th ```sh block under the heading "## $1" ("" = before the first heading),
# without trailing comments.
block() {
    awk -v h="$1" -v n="${2:-1}" '
        BEGIN { insec = (h == "") }
        !inblk && /^## / { insec = ($0 == "## " h); k = 0; next }
        insec && !inblk && /^```sh$/ { k++; if (k == n) inblk = 1; next }
        inblk && /^```$/ { inblk = 0; insec = 0; next }
        inblk { print }' "$readme" | sed -E 's/[[:space:]]+#[^"'\'']*$//'
}

# layer NAME LOWER... : a fresh overlay NAME over the given lower layers (upper dirs, then the
# base), with /proc, /sys, /dev and the source mounted; sets $root.
layer() {
    local name=$1 lowers="" l
    shift
    for l in "$@"; do lowers=${lowers:+$lowers:}$l; done
    root=$check_dir/mnt/$name
    rm -rf "$check_dir/layers/$name"
    mkdir -p "$check_dir/layers/$name/upper" "$check_dir/layers/$name/work" "$root"
    mount -t overlay overlay -o "lowerdir=$lowers,upperdir=$check_dir/layers/$name/upper,workdir=$check_dir/layers/$name/work" "$root"
    mounted+=("$root")
    mount -t proc proc "$root/proc"
    mount -t sysfs sysfs "$root/sys"
    mount --rbind /dev "$root/dev"
    mount --make-rslave "$root/dev"
    mkdir -p "$root/mnt/macdec.git"
    mount --bind "$src" "$root/mnt/macdec.git"
    mount -o remount,bind,ro "$root/mnt/macdec.git"
    cp /etc/resolv.conf "$root/etc/resolv.conf"
    # A site whose HTTPS goes through its own CA lists it here; every machine of the site has it,
    # so the fresh one does too (the README's ca-certificates install then trusts it).
    if compgen -G "/usr/local/share/ca-certificates/*.crt" >/dev/null; then
        mkdir -p "$root/usr/local/share/ca-certificates"
        cp /usr/local/share/ca-certificates/*.crt "$root/usr/local/share/ca-certificates/"
    fi
}
# Is the layer NAME (upper dir) there from this or an earlier run?
have() { [ -d "$check_dir/layers/$1/upper" ]; }
# Move the checkout made by the rust stage to the commit checked (no-op when it is already there).
sync_checkout() {
    chroot "$root" /bin/sh -c 'cd /root/macdec && git fetch -q /mnt/macdec.git HEAD &&
        git checkout -q --detach FETCH_HEAD' >>"$check_dir/logs/sync.log" 2>&1 || {
        echo "check-install-lines: could not update the checkout in $root" >&2
        exit 1
    }
}
up() { echo "$check_dir/layers/$1/upper"; }
release() { # unmount the last layer
    unmount_root "${mounted[-1]}"
    unset 'mounted[-1]'
}

# Run bash code as root in a login shell of the chroot (so ~/.profile's PATH from rustup applies),
# with a clean environment, logging to logs/STAGE.log; print PASS or FAIL with the wall time.
status=0
run_stage() {
    local stage=$1 dir=$2 code=$3 t0=$SECONDS rc=0 log=$check_dir/logs/$1.log
    {
        echo "## $stage (commit $commit), in $dir:"
        echo "$code"
        echo "##"
    } >"$log"
    chroot "$root" /usr/bin/env -i HOME=/root TERM=dumb LANG=C.UTF-8 \
        PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin \
        DEBIAN_FRONTEND=noninteractive ${CARGO_BUILD_JOBS:+CARGO_BUILD_JOBS=$CARGO_BUILD_JOBS} \
        /bin/bash -lc "set -euo pipefail; cd $dir; $code" </dev/null >>"$log" 2>&1 || rc=$?
    local what
    what=$(echo "$code" | paste -sd ';' | sed 's/;/; /g')
    if [ $rc = 0 ]; then
        printf 'PASS %-7s %5ds  %s\n' "$stage" $((SECONDS - t0)) "$what"
    else
        printf 'FAIL %-7s %5ds  %s (exit %d; the end of %s follows)\n' "$stage" $((SECONDS - t0)) "$what" $rc "$log"
        tail -25 "$log" | sed 's/^/    /'
        status=1
    fi
    return $rc
}

want() { local s; for s in "${stages[@]}"; do [ "$s" = "$1" ] && return 0; done; return 1; }
need() { have "$1" || { echo "check-install-lines: run stage $1 first" >&2; exit 2; }; }

echo "check-install-lines: README.md of commit $commit on Debian bookworm ($base)" >&2

if want rust; then
    # The README's "Install" block as a user types it, except: rustup's installer runs without
    # questions (`sh -s -- -y`: the defaults, stable), and the clone is of this checkout's commit.
    # Where sh.rustup.rs does not resolve, the same script from rustup's download server.
    code=$(block Install)
    if ! getent hosts sh.rustup.rs >/dev/null; then
        code=$(echo "$code" | sed 's|https://sh.rustup.rs|https://static.rust-lang.org/rustup/rustup-init.sh|')
    fi
    code=$(echo "$code" | sed -e 's/| sh$/| sh -s -- -y/' -e 's|<URL of this repository>|/mnt/macdec.git|')
    layer rust "$base"
    run_stage rust /root "$code" || true
    release
fi

top=$(block "")
if want train; then
    need rust
    layer train "$(up rust)" "$base"
    sync_checkout
    run_stage train /root/macdec "$(echo "$top" | sed -n 1p)" || true
    release
fi

# test, ros and python start from the built checkout (train) when it is there, else from rust.
built=("$(up rust)" "$base")
have train && built=("$(up train)" "${built[@]}")

if want test; then
    need rust
    layer test "${built[@]}"
    sync_checkout
    run_stage test /root/macdec "$(echo "$top" | sed -n 2p)" || true
    release
fi

if want ros; then
    need rust
    apt_line=$(block "Running on robots with ROS" | grep -m1 '^apt-get .*ros-core')
    smoke=$(block "Running on robots with ROS" 2 | grep -m1 -o '^scripts/ros-smoke.sh')
    layer ros "${built[@]}"
    sync_checkout
    run_stage ros /root/macdec "$apt_line
$smoke" || true
    release
fi

if want python; then
    need rust
    layer python "${built[@]}"
    sync_checkout
    run_stage python /root/macdec "$(block "From Python")" || true
    release
fi

echo "check-install-lines: logs in $check_dir/logs; layers in $check_dir/layers (rm -rf to free)" >&2
exit $status
