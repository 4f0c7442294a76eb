#!/usr/bin/env bash
# Slurm for tests/test_slurm.py: the Debian packages of a single-node cluster (munge, slurmctld,
# slurmd, slurm-client). Only installs them: the test writes its own configuration and starts and
# stops the daemons itself (no systemd). Idempotent: does nothing when the packages are present.
set -euo pipefail

packages=(munge slurmctld slurmd slurm-client)
missing=()
for pkg in "${packages[@]}"; do
    status=$(dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null || true)
    [ "$status" = "install ok installed" ] || missing+=("$pkg")
done
if [ ${#missing[@]} -eq 0 ]; then
    echo "slurm: ${packages[*]} already installed"
    exit 0
fi
if [ "$(id -u)" -ne 0 ]; then
    echo "slurm: not root, cannot install ${missing[*]}; tests/test_slurm.py will be skipped"
    exit 0
fi

export DEBIAN_FRONTEND=noninteractive
apt_opts=(-o DPkg::Lock::Timeout=600 -o Acquire::Retries=3)
# The packages' maintainer scripts start munge, slurmctld and slurmd through invoke-rc.d and fail
# when that fails (slurmd has no configuration yet). Deny service starts during the install, as
# container images do, unless a policy is already in place.
if [ ! -e /usr/sbin/policy-rc.d ]; then
    printf '#!/bin/sh\nexit 101\n' > /usr/sbin/policy-rc.d
    chmod +x /usr/sbin/policy-rc.d
    trap 'rm -f /usr/sbin/policy-rc.d' EXIT
fi
for attempt in 1 2 3; do
    if apt-get "${apt_opts[@]}" update -qq \
        && apt-get "${apt_opts[@]}" install -y -qq --no-install-recommends "${missing[@]}"; then
        break
    fi
    [ "$attempt" -lt 3 ] || { echo "slurm: apt-get install ${missing[*]} failed"; exit 1; }
    sleep $((attempt * 10))
done
echo "slurm: installed ${missing[*]} ($(dpkg-query -W -f='${Version}' slurmd))"
