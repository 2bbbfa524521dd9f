"""The params files the suite writes: strings quoted for rcl, no aliases, values kept."""

from __future__ import annotations

import yaml

from haptic_dob.runtime.params_file import dump_params


def test_string_values_are_quoted_and_read_back_unchanged() -> None:
    shared = [0.1, 0.2]
    doc = {
        "/**/controller_node": {
            "ros__parameters": {"command_token": "4111751691456e08", "mode": "DOB", "j": shared},
        },
        "/**/observer_node": {"ros__parameters": {"j": shared, "names": ("a", "1e5")}},
    }
    text = dump_params(doc)
    assert 'command_token: "4111751691456e08"' in text and 'mode: "DOB"' in text
    assert '- "1e5"' in text
    assert "&id" not in text and "*id" not in text  # rcl refuses anchors and aliases
    back = yaml.safe_load(text)
    assert back["/**/controller_node"]["ros__parameters"]["command_token"] == "4111751691456e08"
    assert back["/**/observer_node"]["ros__parameters"] == {"j": shared, "names": ["a", "1e5"]}
    assert "ros__parameters:" in text  # keys stay plain
