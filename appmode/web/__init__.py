"""The web view of a driving session: `appmode web` serves a page (its assets in
`static/`) that drives the same session objects as the terminal console."""
