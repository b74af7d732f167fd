"""The driving session, apart from any view: keys and commands to letters and frames,
hold-to-drive, parameter and settings queries, messages, recording and the stop. The
terminal console (`console/`) is one view of it. Uses `host` and the layers below."""
