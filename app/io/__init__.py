"""Files and units: yaml_text (the only YAML reader/writer), presets, modes, units and display units, numbers, drive logs."""
