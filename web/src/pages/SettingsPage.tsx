import { useEffect, useState } from 'react';
import { Api, ApiFailure } from '../api/http';
import { ErrorBox } from '../components/ErrorBox';
import { gestureLabel } from '../components/Panels';
import {
  COMMAND_TYPES,
  MAPPABLE_GESTURES,
  type CommandType,
  type Config,
  type GestureProfile,
  type MappableGesture,
  type Mapping,
  type MotionPayload,
} from '../types';
import type { Theme } from '../App';

const PAYLOAD_FIELDS: { key: keyof MotionPayload; label: string }[] = [
  { key: 'vx_m_s', label: 'forward m/s' },
  { key: 'vy_m_s', label: 'right m/s' },
  { key: 'vz_m_s', label: 'up m/s' },
  { key: 'yaw_rate_deg_s', label: 'yaw °/s' },
  { key: 'duration_s', label: 'for s' },
];

interface Props {
  api: Api;
  config: Config | null;
  theme: Theme;
  onConfig(c: Config): void;
}

export function SettingsPage({ api, config, theme, onConfig }: Props) {
  const [profile, setProfile] = useState<GestureProfile | null>(config?.profile ?? null);
  const [failure, setFailure] = useState<ApiFailure | null>(null);
  const [saved, setSaved] = useState<string | null>(null);
  const [adapter, setAdapter] = useState(config?.adapter.name ?? '');
  const [adapterOptions, setAdapterOptions] = useState(
    JSON.stringify(config?.adapter.options ?? {}),
  );

  useEffect(() => {
    if (config) {
      setProfile(config.profile);
      setAdapter(config.adapter.name);
      setAdapterOptions(JSON.stringify(config.adapter.options));
    }
  }, [config]);

  const put = async (update: Parameters<Api['putConfig']>[0], what: string) => {
    setFailure(null);
    setSaved(null);
    try {
      const c = await api.putConfig(update);
      onConfig(c);
      setSaved(`${what} saved.`);
    } catch (e) {
      if (e instanceof ApiFailure) setFailure(e);
    }
  };

  if (!config || !profile) return <p className="muted">Loading settings…</p>;

  const setMapping = (g: MappableGesture, m: Mapping | undefined) => {
    const mappings = { ...profile.mappings };
    if (m) mappings[g] = m;
    else delete mappings[g];
    setProfile({ ...profile, mappings });
  };

  return (
    <div className="page settings">
      <h1>Settings</h1>
      {saved && (
        <p role="status" className="ok">
          {saved}
        </p>
      )}
      <ErrorBox failure={failure} title="The server did not accept this" />
      <section className="panel" aria-labelledby="s-theme">
        <h2 id="s-theme">Theme</h2>
        <fieldset>
          <legend className="sr-only">Colour theme (saved for your account)</legend>
          {(['dark', 'light'] as const).map((t) => (
            <label key={t} className="radio">
              <input
                type="radio"
                name="theme"
                value={t}
                checked={theme === t}
                onChange={() => void put({ theme: t }, 'Theme')}
              />
              {t === 'dark' ? 'Dark' : 'Light'}
            </label>
          ))}
        </fieldset>
      </section>
      <section className="panel" aria-labelledby="s-map">
        <h2 id="s-map">Gesture → command mapping</h2>
        <form
          onSubmit={(e) => {
            e.preventDefault();
            void put({ profile }, 'Mapping');
          }}
        >
          <label>
            Profile name{' '}
            <input
              value={profile.name}
              onChange={(e) => setProfile({ ...profile, name: e.target.value })}
            />
          </label>
          <table className="mapping">
            <thead>
              <tr>
                <th scope="col">Gesture</th>
                <th scope="col">Command</th>
                <th scope="col">Motion (MOVE)</th>
                <th scope="col">Repeat while held</th>
              </tr>
            </thead>
            <tbody>
              {MAPPABLE_GESTURES.map((g) => {
                const m = profile.mappings[g];
                return (
                  <tr key={g}>
                    <th scope="row">{gestureLabel(g)}</th>
                    <td>
                      <select
                        aria-label={`Command for ${gestureLabel(g)}`}
                        data-testid={`map-${g}`}
                        value={m?.command ?? ''}
                        onChange={(e) => {
                          const c = e.target.value as CommandType | '';
                          if (!c) setMapping(g, undefined);
                          else if (c === 'MOVE')
                            setMapping(g, { command: c, payload: m?.payload ?? { duration_s: 1 } });
                          else setMapping(g, { command: c });
                        }}
                      >
                        <option value="">(no command)</option>
                        {COMMAND_TYPES.map((c) => (
                          <option key={c} value={c}>
                            {c}
                          </option>
                        ))}
                      </select>
                    </td>
                    <td className="payload">
                      {m?.command === 'MOVE' &&
                        PAYLOAD_FIELDS.map((f) => (
                          <label key={f.key}>
                            <span className="sr-only">{gestureLabel(g)} </span>
                            {f.label}
                            <input
                              type="number"
                              step="0.1"
                              value={m.payload?.[f.key] ?? ''}
                              onChange={(e) => {
                                const payload = { ...(m.payload ?? {}) };
                                if (e.target.value === '') delete payload[f.key];
                                else payload[f.key] = Number(e.target.value);
                                setMapping(g, { ...m, payload });
                              }}
                            />
                          </label>
                        ))}
                    </td>
                    <td>
                      {m?.command === 'MOVE' && (
                        <input
                          type="checkbox"
                          aria-label={`Repeat ${gestureLabel(g)} while held`}
                          checked={m.repeat_while_held === true}
                          onChange={(e) =>
                            setMapping(g, { ...m, repeat_while_held: e.target.checked })
                          }
                        />
                      )}
                    </td>
                  </tr>
                );
              })}
            </tbody>
          </table>
          <div className="row">
            <button type="submit" className="primary" data-testid="save-mapping">
              Save mapping
            </button>
            <button type="button" onClick={() => setProfile(config.profile)}>
              Undo changes
            </button>
          </div>
        </form>
      </section>
      <section className="panel" aria-labelledby="s-drone">
        <h2 id="s-drone">Drone</h2>
        <p className="muted">
          Switching disconnects the current drone first (it is told to land if flying) and opens a
          new session. Camera source: <code>{config.source}</code>
        </p>
        <form
          onSubmit={(e) => {
            e.preventDefault();
            let options: Record<string, unknown>;
            try {
              options = JSON.parse(adapterOptions || '{}') as Record<string, unknown>;
            } catch (err) {
              setFailure(
                new ApiFailure(0, {
                  error: 'invalid_options',
                  cause: `The adapter options are not JSON (${err instanceof Error ? err.message : String(err)}).`,
                  suggestion:
                    'Write a JSON object, e.g. {"address": "192.168.10.1"}, or {} for none.',
                  request_id: '',
                }),
              );
              return;
            }
            void put({ adapter: { name: adapter, options } }, 'Drone');
          }}
        >
          <label>
            Adapter{' '}
            <select value={adapter} onChange={(e) => setAdapter(e.target.value)}>
              {config.adapters_available.map((a) => (
                <option key={a} value={a}>
                  {a}
                </option>
              ))}
            </select>
          </label>
          <label>
            Options (JSON){' '}
            <input value={adapterOptions} onChange={(e) => setAdapterOptions(e.target.value)} />
          </label>
          <button type="submit">Connect</button>
        </form>
      </section>
    </div>
  );
}
