"""A session on the APP port: pages, letters and the parameters (`session.AppSession`),
its commands (`commands`)."""
