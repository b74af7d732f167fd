"""The driving console: the prompt_toolkit application, the driving session, the status
panel and hold-to-drive. Uses `host` and the layers below."""
