"""Bags rewritten with edited poses, for the commands' tests of bad samples."""

from lumpbeam_ros.core.bagio import BagWriter, read_load_events, read_tip_poses


def rewritten(bag, out, edit):
    """The bag's /tip_pose and /tip_load, the poses' (t, x, z, pitch) rows edited."""
    poses, loads = read_tip_poses(bag), read_load_events(bag)
    rows = edit([list(r) for r in zip(poses.t, poses.x, poses.z, poses.pitch, strict=True)])
    with BagWriter(out) as writer:
        for t, x, z, pitch in rows:
            writer.write_pose('/tip_pose', t, x, z, pitch)
        writer.add_topic('/tip_load', 'std_msgs/msg/Float64')
        for t, kg in zip(loads.t, loads.kg, strict=True):
            writer.write_float('/tip_load', float(t), float(kg))
    return out
