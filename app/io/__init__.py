"""Files and units: yaml_text (the only YAML reader/writer), presets, modes, units, numbers, drive logs."""
