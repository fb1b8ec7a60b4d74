"""click.Choice with the project's "did you mean" on a near miss, as a misspelt material or
indenter name gets it (validate.did_you_mean)."""

from __future__ import annotations

import click


class Choice(click.Choice):
    def convert(self, value, param, ctx):
        try:
            return super().convert(value, param, ctx)
        except click.BadParameter as e:
            from tactileskin.validate import did_you_mean

            hint = did_you_mean(value, [str(c) for c in self.choices]) if isinstance(value, str) else ""
            if not hint:
                raise
            raise click.BadParameter(f"{e.message.rstrip('.')}; {hint}", ctx=ctx, param=param) from None
