"""What the shipped viewer layouts use, checked against a bag: topics, types and message paths.

``config/foxglove_layout.json`` (Foxglove's ``configById`` + ``layout`` tree) and
``config/lumpbeam.rviz`` name topics in their panels. :func:`foxglove_uses` and
:func:`rviz_uses` list each use with what the panel needs: a message type (a 3D or RViz
display draws given types) or a message path whose leaf it plots. :func:`check_uses` then
opens a bag and evaluates every use on its messages, so a renamed topic, a changed type or a
key no message carries is caught without opening a viewer.

Message paths follow Foxglove's syntax as far as the layouts use it: ``/topic.field``,
``[N]`` and ``[:]`` on arrays, and ``{field=="literal"}`` filters.
"""

from __future__ import annotations

import json
import re
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml

from lumpbeam_ros.base.interface import MARKER_ARRAY, POSE_STAMPED
from lumpbeam_ros.core.bagio import BagReader
from lumpbeam_ros.core.bagio.typestore import deserialize

#: 3D panel topics: the types Foxglove's 3D panel draws that the layout relies on.
THREE_D_TYPES = (MARKER_ARRAY, POSE_STAMPED)
#: The message type each RViz display class subscribes with.
RVIZ_DISPLAY_TYPES = {
    'rviz_default_plugins/MarkerArray': MARKER_ARRAY,
    'rviz_default_plugins/Pose': POSE_STAMPED,
}
#: Panels whose ``paths`` are message paths to plotted values.
PATH_PANELS = ('Plot', 'StateTransitions')

_SEGMENT = re.compile(r'\.(\w+)|\[(\d+|:)\]|\{(\w+)==("(?:[^"\\]|\\.)*"|[-\w.]+)\}')
_TOPIC = re.compile(r'/[\w/]*\w')


@dataclass(frozen=True)
class PanelUse:
    """One topic a panel uses.

    Attributes:
        panel: The panel's id (``Plot!tipz``) or display name.
        topic: The topic.
        msgtype: The type the panel needs (``None``: any type the path resolves in).
        path: The message path after the topic (empty: the whole message).
    """

    panel: str
    topic: str
    msgtype: str | None = None
    path: str = ''


def split_message_path(text: str) -> tuple[str, list[tuple[str, str]]]:
    """Splits a Foxglove message path into its topic and segments.

    Args:
        text: E.g. ``/beam_params.status[0].values[:]{key=="damping_ratio"}.value``.

    Returns:
        The topic and ``(kind, value)`` segments: ``('field', name)``, ``('index', 'N' or
        ':')``, ``('filter', 'field==literal')``.

    Raises:
        ValueError: Text that is not a path of this syntax.
    """
    topic = _TOPIC.match(text)
    if topic is None:
        raise ValueError(f'message path {text!r} does not start with a topic')
    rest, segments, at = text[topic.end() :], [], 0
    while at < len(rest):
        match = _SEGMENT.match(rest, at)
        if match is None:
            raise ValueError(f'message path {text!r}: cannot read {rest[at:]!r}')
        field, index, key, literal = match.groups()
        if field is not None:
            segments.append(('field', field))
        elif index is not None:
            segments.append(('index', index))
        else:
            segments.append(('filter', f'{key}=={literal}'))
        at = match.end()
    return topic.group(0), segments


def evaluate(message: Any, segments: Sequence[tuple[str, str]]) -> list[Any]:
    """The values a message path selects in one (rosbags) message.

    Args:
        message: A deserialized message.
        segments: From :func:`split_message_path`.

    Returns:
        Every value selected (empty: the path selects nothing in this message).

    Raises:
        ValueError: A field the message type does not have.
    """
    values = [message]
    for kind, value in segments:
        selected: list[Any] = []
        for item in values:
            if kind == 'field':
                if not hasattr(item, value):
                    raise ValueError(f'{type(item).__name__} has no field {value!r}')
                selected.append(getattr(item, value))
            elif kind == 'index':
                selected += list(item) if value == ':' else list(item)[int(value) : int(value) + 1]
            else:
                key, literal = value.split('==', 1)
                wanted = json.loads(literal) if literal.startswith('"') else literal
                if str(getattr(item, key)) == str(wanted):
                    selected.append(item)
        values = selected
    return values


def _panel_kind(panel_id: str) -> str:
    return panel_id.split('!', 1)[0]


def _tree_panels(node: Any) -> Iterable[str]:
    if isinstance(node, str):
        yield node
    elif isinstance(node, dict):
        for key in ('first', 'second'):
            yield from _tree_panels(node.get(key))


def load_foxglove_layout(path: str | Path) -> dict[str, Any]:
    """Reads a Foxglove layout file and checks its tree names exactly its configured panels.

    Raises:
        ValueError: Not JSON, no ``configById``/``layout``, or panels in one and not the other.
    """
    layout = json.loads(Path(path).read_text(encoding='utf-8'))
    if not isinstance(layout, dict) or 'configById' not in layout or 'layout' not in layout:
        raise ValueError(f'{path}: not a Foxglove layout (no configById and layout)')
    placed = set(_tree_panels(layout['layout']))
    configured = set(layout['configById'])
    if placed != configured:
        raise ValueError(
            f'{path}: panels placed {sorted(placed)} but configured {sorted(configured)}'
        )
    return layout


def foxglove_uses(layout: dict[str, Any]) -> list[PanelUse]:
    """Every topic the panels of a Foxglove layout use."""
    uses = []
    for panel_id, config in layout['configById'].items():
        kind = _panel_kind(panel_id)
        if kind == '3D':
            for topic, settings in config.get('topics', {}).items():
                if settings.get('visible', True):
                    uses.append(PanelUse(panel_id, topic))
        elif kind in PATH_PANELS:
            for entry in config.get('paths', []):
                topic, _ = split_message_path(entry['value'])
                uses.append(PanelUse(panel_id, topic, path=entry['value'][len(topic) :]))
        elif kind == 'RawMessages':
            topic, _ = split_message_path(config['topicPath'])
            uses.append(PanelUse(panel_id, topic, path=config['topicPath'][len(topic) :]))
    return uses


def rviz_uses(path: str | Path) -> list[PanelUse]:
    """Every topic the displays of an RViz config subscribe to, with the type they need.

    Raises:
        ValueError: Not an RViz config, or a display with a topic of an unknown class.
    """
    config = yaml.safe_load(Path(path).read_text(encoding='utf-8'))
    try:
        displays = config['Visualization Manager']['Displays']
    except (TypeError, KeyError):
        raise ValueError(f'{path}: not an RViz config (no Visualization Manager)') from None
    uses = []
    for display in displays:
        topic = (display.get('Topic') or {}).get('Value')
        if topic is None:
            continue
        msgtype = RVIZ_DISPLAY_TYPES.get(display['Class'])
        if msgtype is None:
            raise ValueError(f'{path}: display class {display["Class"]} is not known here')
        uses.append(PanelUse(display['Name'], topic, msgtype))
    return uses


def check_uses(uses: Sequence[PanelUse], bag: str | Path, messages: int = 50) -> list[str]:
    """What in a bag does not serve the uses: missing topics, other types, empty paths.

    A 3D panel use needs one of :data:`THREE_D_TYPES`; a use with a type needs that type; a
    use with a path needs the path to select a value in at least one of the topic's first
    ``messages`` messages (a numeric one, or a string that reads as a number, for plots).

    Args:
        uses: From :func:`foxglove_uses` or :func:`rviz_uses`.
        bag: The bag.
        messages: How many messages of each topic to evaluate paths on.

    Returns:
        One line per problem (empty: everything is served).

    Raises:
        BagError: The bag cannot be read.
    """
    reader = BagReader(bag)
    problems = []
    for use in uses:
        entry = reader.topics.get(use.topic)
        where = f'{use.panel}: {use.topic}'
        if entry is None or entry.count == 0:
            problems.append(f'{where}: not in the bag')
            continue
        wanted = use.msgtype
        if _panel_kind(use.panel) == '3D' and entry.msgtype not in THREE_D_TYPES:
            wanted = ' or '.join(THREE_D_TYPES)
        if wanted is not None and entry.msgtype != wanted:
            problems.append(f'{where}: {entry.msgtype} in the bag, the panel needs {wanted}')
            continue
        if use.path:
            _, segments = split_message_path(use.topic + use.path)
            found = []
            for index, raw in enumerate(reader.iter_raw([use.topic])):
                if index >= messages:
                    break
                found += evaluate(deserialize(raw.data, raw.msgtype), segments)
            if not found:
                problems.append(f'{where}{use.path}: selects nothing in the bag')
            elif _panel_kind(use.panel) in PATH_PANELS and not all(map(_plottable, found)):
                problems.append(f'{where}{use.path}: selects values that are not numbers')
    return problems


def _plottable(value: Any) -> bool:
    if isinstance(value, bool | int | float):
        return True
    try:
        float(value)  # Foxglove plots numeric strings (DiagnosticStatus KeyValues)
    except (TypeError, ValueError):
        return False
    return True
