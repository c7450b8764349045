import subprocess
import sys

import pytest

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.nodes.ros_domain import PRIVATE_DOMAIN_IDS, claim_domain_id

# Holds a claim on the one domain given, says so, and waits for its standard input to close.
_HOLDER = (
    'import sys\n'
    'from lumpbeam_ros.nodes.ros_domain import claim_domain_id\n'
    'claim = claim_domain_id([int(sys.argv[1])])\n'
    'print(claim.domain_id, flush=True)\n'
    'sys.stdin.read()\n'
)


def test_claims_of_one_process_are_distinct_and_private():
    claims = [claim_domain_id() for _ in range(20)]
    try:
        ids = [c.domain_id for c in claims]
        assert len(set(ids)) == 20 and set(ids) <= set(PRIVATE_DOMAIN_IDS)
        assert 0 not in PRIVATE_DOMAIN_IDS
    finally:
        for claim in claims:
            claim.release()


def test_a_domain_held_by_another_process_is_skipped_until_it_exits():
    with claim_domain_id() as probe:
        domain = probe.domain_id
    holder = subprocess.Popen(
        [sys.executable, '-c', _HOLDER, str(domain)],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        assert holder.stdout.readline().strip() == str(domain)
        with pytest.raises(LumpbeamError, match=f'every ROS domain id of {domain}..{domain}'):
            claim_domain_id([domain])
        with claim_domain_id([domain, domain + 1]) as other:
            assert other.domain_id == domain + 1
    finally:
        holder.communicate('')  # end of input: the holder exits without releasing
    with claim_domain_id([domain]) as again:
        assert again.domain_id == domain


def test_release_frees_the_domain_and_is_idempotent():
    claim = claim_domain_id()
    claim.release()
    claim.release()
    with claim_domain_id([claim.domain_id]) as again:
        assert again.domain_id == claim.domain_id


def test_no_candidates_is_an_error():
    with pytest.raises(LumpbeamError, match='no ROS domain id'):
        claim_domain_id([])
