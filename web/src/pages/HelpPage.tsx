import { HAVE_RENDERED_PICTURES, HandPicture } from '../components/HandPicture';
import { gestureLabel, mappingText } from '../components/Panels';
import { ALERT_HELP, ERROR_HELP } from '../logic/alerts';
import { KEY_BINDINGS } from '../logic/keys';
import { MAPPABLE_GESTURES, type Config } from '../types';

const HOW: Record<string, string> = {
  OPEN_PALM: 'All five digits extended, palm to the camera.',
  FIST: 'All five digits folded.',
  THUMB_UP: 'Thumb only, pointing up.',
  THUMB_DOWN: 'Thumb only, pointing down.',
  POINT_UP: 'Index only, pointing up.',
  POINT_LEFT: 'Index only, pointing to the left of the image.',
  POINT_RIGHT: 'Index only, pointing to the right of the image.',
  VICTORY: 'Index and middle finger, spread.',
  I_LOVE_YOU: 'Thumb, index and little finger.',
};

const keyName = (k: string) =>
  ({ ArrowUp: '↑', ArrowDown: '↓', ArrowLeft: '←', ArrowRight: '→' })[k] ?? k.toUpperCase();

export function HelpPage({ config }: { config: Config | null }) {
  return (
    <div className="page help">
      <h1>Help</h1>
      <section aria-labelledby="h-gestures">
        <h2 id="h-gestures">Gestures and the mapping in force</h2>
        <p>
          Hold a gesture steadily in front of the camera: it takes about five frames to be
          recognised.{' '}
          {config ? `Profile in force: “${config.profile.name}”.` : 'Loading the profile…'} Change
          the mapping in Settings.
        </p>
        {!HAVE_RENDERED_PICTURES && (
          <p className="muted">
            These pictures are schematic skeletons: the renders of our hand model are made by
            web/scripts/render-gesture-pictures.sh once the fixtures renderer is built in.
          </p>
        )}
        <ul className="gesture-cards">
          {MAPPABLE_GESTURES.map((g) => (
            <li key={g} className="panel">
              <HandPicture gesture={g} label={`${gestureLabel(g)}: ${HOW[g] ?? ''}`} />
              <h3>{gestureLabel(g)}</h3>
              <p>{HOW[g]}</p>
              <p>
                <span className="label">Command: </span>
                <strong data-testid={`help-map-${g}`}>
                  {config ? mappingText(config.profile.mappings[g]) : '…'}
                </strong>
              </p>
            </li>
          ))}
        </ul>
      </section>
      <section aria-labelledby="h-keys">
        <h2 id="h-keys">Keyboard</h2>
        <table>
          <thead>
            <tr>
              <th scope="col">Key</th>
              <th scope="col">Action (flying view)</th>
            </tr>
          </thead>
          <tbody>
            <tr>
              <td>
                <kbd>Space</kbd>
              </td>
              <td>
                <strong>Emergency stop</strong> (motors off at once; latched until released)
              </td>
            </tr>
            {KEY_BINDINGS.map((b) => (
              <tr key={b.send}>
                <td>
                  {b.keys.map((k, i) => (
                    <span key={k}>
                      {i > 0 && ' or '}
                      <kbd>{keyName(k)}</kbd>
                    </span>
                  ))}
                </td>
                <td>{b.label}</td>
              </tr>
            ))}
            <tr>
              <td>
                <kbd>Tab</kbd> / <kbd>Shift+Tab</kbd>
              </td>
              <td>Move between controls; Enter activates</td>
            </tr>
            <tr>
              <td>
                <kbd>Space</kbd> / <kbd>K</kbd>, <kbd>←</kbd> <kbd>→</kbd>
              </td>
              <td>Replay view: play/pause; on the timeline, seek</td>
            </tr>
          </tbody>
        </table>
        <p>
          Movement keys fly while held; releasing one makes the drone hover. Keys go through the
          same commands, arbiter and failsafes as gestures.
        </p>
      </section>
      <section aria-labelledby="h-alerts">
        <h2 id="h-alerts">Alerts</h2>
        <table>
          <thead>
            <tr>
              <th scope="col">Code</th>
              <th scope="col">Severity</th>
              <th scope="col">What it means</th>
              <th scope="col">What to do</th>
            </tr>
          </thead>
          <tbody>
            {ALERT_HELP.map((a) => (
              <tr key={a.code}>
                <td>
                  <code>{a.code}</code>
                </td>
                <td>{a.severity}</td>
                <td>{a.meaning}</td>
                <td>{a.action}</td>
              </tr>
            ))}
          </tbody>
        </table>
        <p>
          Critical alerts sound an alarm. Warnings and critical alerts stay until you acknowledge
          them (or the condition clears, e.g. LINK_RESTORED); information can be cleared.
        </p>
      </section>
      <section aria-labelledby="h-errors">
        <h2 id="h-errors">Errors</h2>
        <table>
          <thead>
            <tr>
              <th scope="col">Error</th>
              <th scope="col">What it means</th>
              <th scope="col">What to do</th>
            </tr>
          </thead>
          <tbody>
            {ERROR_HELP.map((e) => (
              <tr key={e.error}>
                <td>
                  <code>{e.error}</code>
                </td>
                <td>{e.meaning}</td>
                <td>{e.action}</td>
              </tr>
            ))}
          </tbody>
        </table>
        <p>Every error shows the server’s own cause and suggestion and a request id for the log.</p>
      </section>
    </div>
  );
}
