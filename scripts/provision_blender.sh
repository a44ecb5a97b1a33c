#!/usr/bin/env bash
# Provision real Blender binaries, each in its own Debian root made by debootstrap:
#   scripts/provision_blender.sh                 # trixie (Blender 4.3.x) and unstable (5.2.x)
#   scripts/provision_blender.sh trixie          # one suite
# Each root holds blender, python3-numpy, Xvfb, xdotool, Mesa's software OpenGL (llvmpipe) and
# the X utilities used for screenshots (xwd, netpbm). Roots are cached outside the repository in
# $VG_BLENDER_CACHE (default /var/cache/vg-blender), one directory per suite; a finished root is
# reused as it is (delete its directory to rebuild it). Needs root and network access to the
# Debian mirror this machine's apt already uses (read from /etc/apt, never written here).
# Commands are run inside a root with scripts/blender_root.sh.
# Exit status: 0 every requested root is ready; 1 one failed (the others are still built);
# 2 this machine cannot build roots at all (the reason is printed).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
cache=${VG_BLENDER_CACHE:-/var/cache/vg-blender}
# python3-cattr and python3-requests: Blender 5.x's bundled extensions add-on (bl_pkg) imports them
# at startup, and Debian's blender package does not pull them in (without them Blender prints a
# traceback on every start).
packages=(blender python3-numpy python3-cattr python3-requests xvfb xauth xdotool x11-apps netpbm
    libgl1-mesa-dri libglx-mesa0 libegl-mesa0 libgl1 mesa-utils)
stamp_text="vg-blender-root v1: ${packages[*]}"
install_packages="apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq ${packages[*]} && apt-get clean"

die() { # die STATUS MESSAGE
    echo "provision_blender: $2" >&2
    exit "$1"
}

host_mirror() {
    # The URI of the host's main Debian archive, from one-line .list files or deb822 .sources.
    local files=() file
    for file in /etc/apt/sources.list /etc/apt/sources.list.d/*.list /etc/apt/sources.list.d/*.sources; do
        [ -f "$file" ] && files+=("$file")
    done
    [ ${#files[@]} -gt 0 ] || return 1
    awk '
        function consider(uri, suites,   n, parts, i) {
            n = split(suites, parts, /[ \t]+/)
            for (i = 1; i <= n; i++)
                if (parts[i] != "" && parts[i] !~ /-(security|updates|backports)$/ &&
                    uri !~ /security/ && !found) { print uri; found = 1 }
        }
        function flush() {  # end of a deb822 stanza
            if (types ~ /(^|[ \t])deb([ \t]|$)/ && (debian || uri ~ /debian/)) consider(uri, suites)
            types = uri = suites = ""; debian = 0
        }
        FNR == 1 { flush(); deb822 = FILENAME ~ /\.sources$/ }
        deb822 && /^[ \t]*$/ { flush(); next }
        deb822 && /^Types:/ { sub(/^Types:[ \t]*/, ""); types = $0 }
        deb822 && /^URIs:/ { sub(/^URIs:[ \t]*/, ""); split($0, u, /[ \t]+/); uri = u[1] }
        deb822 && /^Suites:/ { sub(/^Suites:[ \t]*/, ""); suites = $0 }
        deb822 && /^Signed-By:.*debian-archive-keyring/ { debian = 1 }
        deb822 { next }
        /^[ \t]*deb[ \t]/ {
            i = 2; if ($2 ~ /^\[/) { while ($i !~ /\]$/) i++; i++ }
            if ($i ~ /debian/) consider($i, $(i + 1))
        }
        END { flush() }
    ' "${files[@]}"
}

[ "$(id -u)" -eq 0 ] || die 2 "needs root (debootstrap, chroot and mounts); run it as root"
mirror=${VG_DEBIAN_MIRROR:-$(host_mirror | head -n 1)}
[ -n "$mirror" ] || die 2 "no Debian archive found in /etc/apt/sources.list* (set VG_DEBIAN_MIRROR)"
if ! command -v debootstrap >/dev/null 2>&1; then
    echo "provision_blender: installing debootstrap on the host" >&2
    { apt-get update -qq && apt-get install -y -qq debootstrap >/dev/null; } ||
        die 2 "debootstrap is not installed and apt-get could not install it"
fi
keyring=/usr/share/keyrings/debian-archive-keyring.gpg
[ -f "$keyring" ] || die 2 "$keyring is missing (install debian-archive-keyring)"

suites=("$@")
[ ${#suites[@]} -gt 0 ] || suites=(trixie unstable)
mkdir -p "$cache"

build_root() { # build_root SUITE
    local suite=$1 root="$cache/$1" work="$cache/$1.partial"
    if [ -f "$root/.vg-root" ] && [ "$(cat "$root/.vg-root")" = "$stamp_text" ]; then
        echo "provision_blender: $suite: cached in $root" >&2
        return 0
    fi
    if [ -f "$root/.vg-root" ]; then
        # A root made for an older package list: add what is missing rather than rebuild it.
        echo "provision_blender: $suite: adding packages to $root" >&2
        if "$here/blender_root.sh" "$suite" -- sh -c "$install_packages" >>"$cache/$suite.log" 2>&1; then
            echo "$stamp_text" >"$root/.vg-root"
            echo "provision_blender: $suite: ready in $root" >&2
            return 0
        fi
        echo "provision_blender: $suite: adding packages failed; rebuilding the root" >&2
    fi
    echo "provision_blender: $suite: building in $work from $mirror (several minutes)" >&2
    rm -rf "$work"
    # minbase keeps the root small; apt inside the root then resolves blender's dependencies.
    debootstrap --variant=minbase --keyring="$keyring" "$suite" "$work" "$mirror" \
        >"$cache/$suite.log" 2>&1 || {
        echo "provision_blender: $suite: debootstrap failed, last lines of $cache/$suite.log:" >&2
        tail -n 15 "$cache/$suite.log" >&2
        return 1
    }
    ln -sf /proc/self/mounts "$work/etc/mtab" # Blender reads /etc/mtab
    # An archive snapshot's Release file may be past its Valid-Until date (unstable's is short).
    echo 'Acquire::Check-Valid-Until "false";' >"$work/etc/apt/apt.conf.d/99vg-snapshot"
    echo 'APT::Install-Recommends "false";' >"$work/etc/apt/apt.conf.d/99vg-no-recommends"
    if ! VG_BLENDER_ROOT="$work" "$here/blender_root.sh" "$suite" -- sh -c "$install_packages" \
        >>"$cache/$suite.log" 2>&1; then
        echo "provision_blender: $suite: installing ${packages[*]} failed; last lines of $cache/$suite.log:" >&2
        tail -n 15 "$cache/$suite.log" >&2
        return 1
    fi
    echo "$stamp_text" >"$work/.vg-root"
    rm -rf "$root"
    mv "$work" "$root"
    echo "provision_blender: $suite: ready in $root" >&2
}

status=0
for suite in "${suites[@]}"; do
    # One builder per suite at a time; a second caller waits, then finds the root cached.
    exec 9>"$cache/.lock-$suite"
    flock 9
    build_root "$suite" || status=1
    exec 9>&-
    if [ -f "$cache/$suite/.vg-root" ]; then
        version=$("$here/blender_root.sh" "$suite" -- blender --version 2>/dev/null | head -n 1) || version="blender does not start"
        echo "$suite: $version"
    fi
done
exit $status
