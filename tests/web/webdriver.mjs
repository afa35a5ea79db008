// A minimal W3C WebDriver client over fetch, for Debian's chromedriver and
// chromium (tests only: open a page, run script in it, click, screenshot).
const ELEMENT = 'element-6066-11e4-a52e-4f735466cecf';

export class WebDriver {
  constructor(base) { this.base = base; this.session = null; }

  async cmd(method, path, body) {
    const res = await fetch(this.base + path, {
      method, headers: { 'Content-Type': 'application/json' }, body: body === undefined ? undefined : JSON.stringify(body),
      signal: AbortSignal.timeout(30000),
    });
    const json = await res.json();
    if (!res.ok) throw new Error(`WebDriver ${method} ${path}: ${json.value && (json.value.message || json.value.error)}`);
    return json.value;
  }

  async start(binary, args) {
    const v = await this.cmd('POST', '/session', {
      capabilities: { alwaysMatch: { browserName: 'chrome', 'goog:chromeOptions': { binary, args } } },
    });
    this.session = v.sessionId;
    this.capabilities = v.capabilities;
  }

  s(path) { return `/session/${this.session}${path}`; }
  open(url) { return this.cmd('POST', this.s('/url'), { url }); }
  // Runs `script` (a function body; may return a promise) with `args` in the page.
  run(script, ...args) { return this.cmd('POST', this.s('/execute/sync'), { script, args }); }
  async click(css) {
    const el = await this.cmd('POST', this.s('/element'), { using: 'css selector', value: css });
    return this.cmd('POST', this.s(`/element/${el[ELEMENT]}/click`), {});
  }
  async screenshot() { return Buffer.from(await this.cmd('GET', this.s('/screenshot')), 'base64'); }
  async quit() { if (this.session) await this.cmd('DELETE', this.s('')).catch(() => {}); this.session = null; }
}
