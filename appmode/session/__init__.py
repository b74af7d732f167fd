"""The driving session, apart from any view: keys and commands to letters and frames,
hold-to-drive, queries, messages, recording and the stop authority. `opener.open_session`
opens one from a board choice; `app/` drives the APP port (`app.session.AppSession`),
`control/` the control port (`control.session.ControlSession`), each with its commands
and what it shows (`status`); what both share is here (`base`, `command_line`,
`authority`, `hold` and its `timeouts`, `instruments`, `rows`). The console and the page
are views of it. Uses `host` and the layers below."""
