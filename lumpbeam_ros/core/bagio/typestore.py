"""The message type system of bags: rosbags' ROS 2 Jazzy typestore.

Bags are written and read without ROS: message classes, CDR (de)serialization, message
definitions (the text a reader needs to decode a type it does not know) and RIHS01 type
hashes all come from rosbags' built-in Jazzy store, which holds common_interfaces.
"""

from __future__ import annotations

import struct
from collections.abc import Iterable
from functools import lru_cache
from typing import Any

from rosbags.serde import SerdeError
from rosbags.typesys import Stores, get_typestore
from rosbags.typesys.store import Typestore

from lumpbeam_ros.base.errors import BagError


@lru_cache(maxsize=1)
def typestore() -> Typestore:
    """Returns the shared ROS 2 Jazzy typestore (built once; it takes ~50 ms)."""
    return get_typestore(Stores.ROS2_JAZZY)


def is_known(msgtype: str) -> bool:
    """Tells whether a type such as ``'std_msgs/msg/Float64'`` is in the typestore."""
    return msgtype in typestore().types


def message_class(msgtype: str) -> type[Any]:
    """Returns the rosbags class of a message type.

    Args:
        msgtype: Full type name, e.g. ``'geometry_msgs/msg/PoseStamped'``.

    Returns:
        The message dataclass.

    Raises:
        BagError: The type is not a ROS 2 Jazzy common_interfaces type.
    """
    try:
        return typestore().types[msgtype]
    except KeyError:
        raise BagError(f'unknown message type {msgtype!r} (not in ROS 2 Jazzy)') from None


def type_description(msgtype: str) -> tuple[str, str]:
    """Returns the ``ros2msg`` definition text and the RIHS01 hash of a type.

    Args:
        msgtype: Full type name.

    Returns:
        ``(msgdef, rihs01)``: the concatenated definition (dependencies after
        ``MSG:`` separators, as ``ros2 bag record`` stores it) and the type hash.

    Raises:
        BagError: Unknown type.
    """
    message_class(msgtype)
    store = typestore()
    msgdef, _ = store.generate_msgdef(msgtype, ros_version=2)
    return msgdef, store.hash_rihs01(msgtype)


def prepare(msgtypes: Iterable[str]) -> None:
    """Builds the typestore and the CDR code of ``msgtypes`` now, not at their first message.

    rosbags generates a type's (de)serializers (and those of the types it nests) when it
    first meets the type, and the store itself takes ~50 ms to build: together some 100 ms,
    three times that on a busy machine, which a live node would otherwise spend on its
    first frame while the next ones queue.

    Args:
        msgtypes: Full type names.

    Raises:
        BagError: An unknown type.
    """
    for msgtype in msgtypes:
        message_class(msgtype)
        typestore().get_msgdef(msgtype)


def serialize(message: Any) -> bytes:
    """Serializes a rosbags message to little-endian CDR.

    Args:
        message: An instance of a typestore class.

    Returns:
        The CDR bytes, with the 4-byte encapsulation header.
    """
    return bytes(typestore().serialize_cdr(message, message.__msgtype__))


def deserialize(data: bytes | memoryview, msgtype: str) -> Any:
    """Deserializes CDR bytes.

    Args:
        data: The serialized message.
        msgtype: Its full type name.

    Returns:
        The message.

    Raises:
        BagError: Unknown type, or bytes that are not a valid message of that type.
    """
    message_class(msgtype)
    try:
        return typestore().deserialize_cdr(data, msgtype)
    except (
        SerdeError,
        struct.error,
        ValueError,
        IndexError,
        AssertionError,
        UnicodeDecodeError,
    ) as exc:
        raise BagError(f'corrupt {msgtype} message ({len(data)} bytes): {exc}') from None
