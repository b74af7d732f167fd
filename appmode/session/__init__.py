"""The driving session, apart from any view: keys, commands and twists (SI velocities,
`base.BaseSession.move`) to letters and frames, the car's twist from its records
(`sensing`), hold-to-drive, queries, messages, recording and the stop authority.
`opener.open_session` opens one from a board choice; `app/` drives the APP port
(`app.session.AppSession`), `control/` the control port
(`control.session.ControlSession`), each with its commands, what it shows (`status`) and
what a twist is on that port (`velocity`); what both share is here (`base`,
`command_line`, `authority`, `hold` and its `timeouts`, `instruments`, `rows`). The
console and the page are views of it. Uses `host` and the layers below."""
