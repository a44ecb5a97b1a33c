#!/usr/bin/env bash
# Run a command inside a Blender root made by scripts/provision_blender.sh:
#   scripts/blender_root.sh SUITE [--bind HOST_DIR ROOT_DIR]... [--ro-bind HOST_DIR ROOT_DIR]...
#                           [--env NAME=VALUE]... -- COMMAND [ARG]...
# e.g. scripts/blender_root.sh trixie --ro-bind "$PWD" /vg/repo -- blender -b --version
# The command runs chrooted, with /proc, /dev, /sys and the given directories mounted. All mounts
# are made in a private mount namespace (unshare), so the host never sees them and they vanish
# when the command ends, whatever way it ends; a trap also unmounts them in order on a normal exit.
# The exit status is the command's. Needs root.
set -euo pipefail
cache=${VG_BLENDER_CACHE:-/var/cache/vg-blender}

usage() {
    sed -n '2,9p' "$0" | sed 's/^# \{0,1\}//' >&2
    exit 2
}

[ $# -ge 1 ] || usage
if [ -z "${VG_BLENDER_NS:-}" ]; then
    [ "$(id -u)" -eq 0 ] || {
        echo "blender_root: needs root (chroot and mounts)" >&2
        exit 2
    }
    VG_BLENDER_NS=1 exec unshare --mount --propagation private "$0" "$@"
fi

suite=$1
shift
root=${VG_BLENDER_ROOT:-$cache/$suite}
[ -x "$root/bin/sh" ] || {
    echo "blender_root: no root for '$suite' in $root (run scripts/provision_blender.sh $suite)" >&2
    exit 2
}
binds=()  # triples: HOST ROOT_DIR MODE
envs=()
while [ $# -gt 0 ]; do
    case $1 in
    --bind | --ro-bind)
        [ $# -ge 3 ] || usage
        binds+=("$2" "$3" "$1")
        shift 3
        ;;
    --env)
        [ $# -ge 2 ] || usage
        envs+=("$2")
        shift 2
        ;;
    --)
        shift
        break
        ;;
    *) usage ;;
    esac
done
[ $# -gt 0 ] || usage

mounted=()
cleanup() {
    local i
    for ((i = ${#mounted[@]} - 1; i >= 0; i--)); do
        umount -R "${mounted[i]}" 2>/dev/null || umount -l "${mounted[i]}" 2>/dev/null || true
    done
}
trap cleanup EXIT
trap 'exit 143' TERM
trap 'exit 130' INT

mount_into() { # mount_into TARGET MOUNT-ARGS...
    local target=$1
    shift
    mkdir -p "$target"
    mount "$@" "$target"
    mounted+=("$target")
}
mount_into "$root/proc" -t proc proc
mount_into "$root/sys" --rbind /sys
mount_into "$root/dev" --rbind /dev
for ((i = 0; i < ${#binds[@]}; i += 3)); do
    host=${binds[i]} target=$root${binds[i + 1]}
    mount_into "$target" --bind "$host"
    if [ "${binds[i + 2]}" = --ro-bind ]; then
        mount -o remount,bind,ro "$target"
    fi
done

chroot "$root" /usr/bin/env -i PATH=/usr/local/bin:/usr/bin:/bin:/usr/sbin:/sbin \
    HOME=/root LANG=C.UTF-8 TERM="${TERM:-dumb}" "${envs[@]}" "$@" <&0 &
child=$!
trap 'kill -TERM $child 2>/dev/null; wait $child; exit 143' TERM
trap 'kill -INT $child 2>/dev/null; wait $child; exit 130' INT
status=0
wait $child || status=$?
exit $status
